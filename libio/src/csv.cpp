// Column files (awcc/recording.hpp): CSV, TSV, semicolon-separated with
// decimal commas, and LabVIEW .lvm text.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

#include "awcc/detail/time_base.hpp"
#include "awcc/units.hpp"
#include "reader_support.hpp"

namespace awcc::detail {

namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------
// CSV / TSV.

std::vector<std::string_view> split(std::string_view line, char delimiter) {
  std::vector<std::string_view> cells;
  if (delimiter != ' ' && line.find('"') != std::string_view::npos) {
    // Quoted cells ("0,001";"1,5"): split outside the quotes; trim() drops the quotes.
    bool quoted = false;
    std::size_t start = 0;
    for (std::size_t i = 0; i < line.size(); ++i) {
      if (line[i] == '"') quoted = !quoted;
      else if (line[i] == delimiter && !quoted) {
        cells.push_back(line.substr(start, i - start));
        start = i + 1;
      }
    }
    cells.push_back(line.substr(start));
    return cells;
  }
  if (delimiter == ' ') {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      if (i >= line.size()) break;
      std::size_t j = i;
      while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
      cells.push_back(line.substr(i, j - i));
      i = j;
    }
    return cells;
  }
  std::size_t start = 0;
  for (;;) {
    const std::size_t end = line.find(delimiter, start);
    cells.push_back(line.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return cells;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '"')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '"')) s.remove_suffix(1);
  return s;
}

bool parse_number(std::string_view cell, double& value) {
  cell = trim(cell);
  if (cell.empty()) return false;
  const char* first = cell.data();
  if (*first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, cell.data() + cell.size(), value);
  return ec == std::errc{} && ptr == cell.data() + cell.size();
}

// Lines longer than this are not rows of a column file; refusing them keeps
// memory bounded whatever the file holds.
constexpr std::size_t kMaxCsvLine = 1 << 20;

// std::getline, but refusing lines longer than kMaxCsvLine.
bool bounded_getline(std::istream& in, std::string& line, const fs::path& path, std::int64_t number) {
  line.clear();
  for (;;) {
    const int c = in.get();
    if (c == std::char_traits<char>::eof()) return !line.empty();  // a last line without newline counts
    if (c == '\n') return true;
    line.push_back(static_cast<char>(c));
    if (line.size() > kMaxCsvLine) {
      reader_fail(path, fmt::format("line {} is longer than {} bytes: not a column file (or a damaged one)", number,
                             kMaxCsvLine));
    }
  }
}

// Column files as labs write them: comma, tab, semicolon or blank
// separated; a decimal point or (European locales) a decimal comma; an
// optional header row; LabVIEW .lvm text (header blocks ending in
// ***End_of_Header***, X_Value as time, Delta_X as the sample interval, an
// empty Comment column). Separator and decimal mark come from the content
// (or the .lvm header); the time column from its name (time, t, zeit, temps,
// tiempo, X_Value, with a unit in brackets) or from its values (strictly
// increasing with a constant step, when the file has at least three columns).
class CsvRecording final : public Recording {
 public:
  CsvRecording(const fs::path& path, const ReaderOptions& options) : in_(path, std::ios::binary) {
    if (!in_) reader_fail(path, "cannot open for reading");
    info_.path = path;
    std::int64_t number = 0;
    const auto lvm = read_lvm_header(number);
    const auto sample = first_rows(number);
    choose_separators(sample, options, lvm);
    const auto table = choose_columns(sample, options);
    choose_time_column(sample, table, options);
    if (lvm.channels && *lvm.channels != info_.channels) {
      std::string names;
      for (const auto& n : info_.channel_names) names += (names.empty() ? "'" : ", '") + n + "'";
      reader_fail(path, fmt::format("its header's Channels line says {} channels, but its rows hold {} data column{} "
                                    "({}): the header does not describe the data; correct the Channels line or "
                                    "the columns",
                                    *lvm.channels, info_.channels, info_.channels == 1 ? "" : "s", names));
    }
    data_start_ = sample.starts[table.first_data];
    first_line_ = sample.lines[table.first_data] - 1;
    in_.clear();
    in_.seekg(data_start_);
    line_ = first_line_;
    info_.fs = sampling_rate(table, options, lvm.delta);
    info_.volts_known = true;
    info_.quantum = 0.0;
    std::string tips;
    for (const auto& n : info_.channel_names) tips += (tips.empty() ? "'" : ", '") + n + "'";
    info_.description = fmt::format(
        "{} ({} columns, {} separated, decimal {}{}{}; channels {})", lvm.lvm ? "LabVIEW text" : "CSV", columns_,
        delimiter_ == '\t' ? "tab" : (delimiter_ == ' ' ? "blank" : fmt::format("'{}'", delimiter_)),
        decimal_ == ',' ? "comma" : "point", table.header ? ", header row" : "",
        time_column_ >= 0 ? fmt::format(", time in '{}'", table.names[static_cast<std::size_t>(time_column_)]) : "",
        tips);
    rewind();
  }

  std::int64_t read(std::span<float> out, std::int64_t max_frames) override {
    std::int64_t n = 0;
    std::string line;
    while (n < max_frames && bounded_getline(in_, line, info_.path, line_ + 1)) {
      ++line_;
      if (trim(line).empty()) continue;
      if (lvm_ && trim(line).starts_with("Channels")) {
        skip_lvm_segment(line);
        continue;
      }
      const auto cells = split(line, delimiter_);
      if (!fits(cells)) {
        reader_fail(info_.path, fmt::format("line {} has {} cells where the first row has {}; fix or remove the line", line_,
                                     cells.size(), columns_));
      }
      int k = 0;
      for (int c : data_columns_) {
        double v;
        if (!number_of(cells[static_cast<std::size_t>(c)], v)) {
          reader_fail(info_.path, fmt::format("line {}, column {}: '{}' is not a number; fix the cell or remove the line",
                                       line_, c + 1, trim(cells[static_cast<std::size_t>(c)])));
        }
        if (!std::isfinite(v)) {
          reader_fail(info_.path, fmt::format("line {}, column {}: the value is not finite; the recording is damaged", line_, c + 1));
        }
        // Samples are 32-bit floats: a larger magnitude would become infinite.
        if (std::fabs(v) > static_cast<double>(std::numeric_limits<float>::max())) {
          reader_fail(info_.path, fmt::format("line {}, column {}: {:g} lies beyond the range of a sample (+/- 3.4e38); the "
                                       "recording is damaged: fix the cell or remove the line", line_, c + 1, v));
        }
        out[static_cast<std::size_t>(n * info_.channels + k++)] = static_cast<float>(v);
      }
      ++n;
    }
    return n;
  }

  void rewind() override {
    in_.clear();
    in_.seekg(data_start_);
    line_ = first_line_;
  }

 private:
  // What a LabVIEW .lvm header states; lvm false for other files.
  struct LvmHeader {
    bool lvm = false;
    std::optional<double> delta;  // Delta_X, the sample interval
    std::optional<int> channels;  // Channels, the segment's data channels
    char separator = 0, decimal = 0;
  };

  // One line of a LabVIEW header: the keys the reader uses. Tab separates
  // key and value (a file written with Separator Comma: a comma).
  static void read_lvm_line(std::string_view line, LvmHeader& h) {
    const auto cells = split(line, line.find('\t') != std::string_view::npos ? '\t' : ',');
    const auto key = cells.empty() ? std::string_view{} : trim(cells[0]);
    const auto value = cells.size() > 1 ? trim(cells[1]) : std::string_view{};
    if (key == "Separator") h.separator = value == "Comma" ? ',' : (value == "Tab" ? '\t' : 0);
    if (key == "Decimal_Separator" && !value.empty()) h.decimal = value[0];
    if (key == "Channels") {
      double n;
      if (parse_number(value, n) && n >= 0.0 && n < 1e6 && n == std::floor(n)) h.channels = static_cast<int>(n);
    }
    if (key == "Delta_X") {
      double d;
      std::string v(value);
      std::replace(v.begin(), v.end(), ',', '.');
      if (parse_number(v, d) && d > 0.0) h.delta = d;
    }
  }

  // A later segment of a LabVIEW file (LabVIEW starts one at every write
  // unless told to write one header only): its header, from its Channels
  // line to ***End_of_Header***, and the column names after it are skipped;
  // its channels and sample interval must be the first segment's.
  void skip_lvm_segment(const std::string& first) {
    LvmHeader h;
    const std::int64_t start = line_;
    std::string line = first;
    for (;;) {
      read_lvm_line(line, h);
      if (trim(line).starts_with("***End_of_Header***")) break;
      if (!bounded_getline(in_, line, info_.path, line_ + 1)) {
        reader_fail(info_.path,
                    fmt::format("the LabVIEW segment header at line {} has no ***End_of_Header***: the file "
                                "is truncated or damaged",
                                start));
      }
      ++line_;
    }
    const auto& f = first_segment_;
    if (h.channels && f.channels && *h.channels != *f.channels) {
      reader_fail(info_.path, fmt::format("the LabVIEW segment at line {} has {} channels, the first segment {}: save "
                                          "the segments as separate files",
                                          start, *h.channels, *f.channels));
    }
    if (h.delta && f.delta && std::fabs(*h.delta - *f.delta) > 1e-6 * *f.delta) {
      reader_fail(info_.path,
                  fmt::format("the LabVIEW segment at line {} has Delta_X {:g} s, the first segment {:g} s: "
                              "its sampling rate differs; save the segments as separate files",
                              start, *h.delta, *f.delta));
    }
    // The column names (a row that is not numbers), if the segment repeats them.
    const std::streampos at = in_.tellg();
    const std::int64_t at_line = line_;
    while (bounded_getline(in_, line, info_.path, line_ + 1)) {
      ++line_;
      if (trim(line).empty()) continue;
      double v;
      const auto cells = split(line, delimiter_);
      if (!cells.empty() && !number_of(cells[0], v)) return;
      break;
    }
    in_.clear();
    in_.seekg(at);
    line_ = at_line;
  }

  // LabVIEW .lvm: header blocks up to the last ***End_of_Header*** before the
  // data, leaving the stream at the data and `number` at the last header line.
  LvmHeader read_lvm_header(std::int64_t& number) {
    const fs::path& path = info_.path;
    LvmHeader h;
    std::string line;
    int markers = 0;
    std::streampos body = 0;
    std::int64_t body_line = 0;
    std::streampos at = in_.tellg();
    if (bounded_getline(in_, line, path, 1) && trim(line).starts_with("LabVIEW Measurement")) h.lvm = true;
    in_.clear();
    in_.seekg(at);
    if (!h.lvm) return h;
    while (bounded_getline(in_, line, path, ++number)) {
      read_lvm_line(line, h);
      if (trim(line).starts_with("***End_of_Header***")) {
        body = in_.tellg();
        body_line = number;
        // The file header, then the first segment's: its data follow.
        // Later segments' headers, inside the data, read() skips.
        if (++markers == 2) break;
      }
    }
    lvm_ = h.lvm;
    first_segment_ = h;
    if (body_line == 0) reader_fail(path, "a LabVIEW measurement file without ***End_of_Header***: not a recording", "not_a_recording");
    in_.clear();
    in_.seekg(body);
    number = body_line;
    return h;
  }

  // The first non-blank rows, their line numbers and where they start: what
  // separator, decimal mark, header and columns are judged from.
  struct Sample {
    std::vector<std::string> rows;
    std::vector<std::int64_t> lines;
    std::vector<std::streampos> starts;
  };

  Sample first_rows(std::int64_t number) {
    Sample sample;
    std::string line;
    while (sample.rows.size() < 50) {
      const std::streampos at = in_.tellg();
      if (!bounded_getline(in_, line, info_.path, ++number)) break;
      if (trim(line).empty()) continue;
      sample.rows.push_back(line);
      sample.lines.push_back(number);
      sample.starts.push_back(at);
    }
    if (sample.rows.empty()) reader_fail(info_.path, "the file holds no rows", "not_a_recording");
    return sample;
  }

  void choose_separators(const Sample& sample, const ReaderOptions& options, const LvmHeader& lvm) {
    const auto& rows = sample.rows;
    auto in_every = [&](char c) {
      return std::all_of(rows.begin(), rows.end(), [c](const std::string& r) { return r.find(c) != std::string::npos; });
    };
    delimiter_ = options.csv.delimiter ? options.csv.delimiter : lvm.separator;
    if (!delimiter_) {
      if (in_every('\t')) delimiter_ = '\t';
      else if (in_every(';')) delimiter_ = ';';
      else if (in_every(',')) delimiter_ = ',';
      else delimiter_ = ' ';
    }
    decimal_ = lvm.decimal ? lvm.decimal : '.';
    if (!lvm.decimal && delimiter_ != ',') {
      // A decimal comma: digits on both sides of a comma in a cell, and no decimal point.
      bool comma = false, point = false;
      for (std::size_t r = rows.size() > 1 ? 1 : 0; r < rows.size(); ++r) {
        for (auto cell : split(rows[r], delimiter_)) {
          cell = trim(cell);
          for (std::size_t k = 1; k + 1 < cell.size(); ++k) {
            const bool digits = std::isdigit(static_cast<unsigned char>(cell[k - 1])) &&
                                std::isdigit(static_cast<unsigned char>(cell[k + 1]));
            if (cell[k] == ',' && digits) comma = true;
            if (cell[k] == '.' && digits) point = true;
          }
        }
      }
      if (comma && !point) decimal_ = ',';
    }
  }

  // The table's shape: a header row or none, the column names and the
  // columns that hold no samples.
  struct Table {
    bool header = false;
    std::size_t first_data = 0;
    std::vector<std::string> names;
    std::vector<bool> skip;
  };

  Table choose_columns(const Sample& sample, const ReaderOptions& options) {
    const fs::path& path = info_.path;
    const auto& rows = sample.rows;
    Table t;
    const auto first = split(rows[0], delimiter_);
    bool all_numbers = true;
    double v;
    for (auto c : first) all_numbers = all_numbers && (trim(c).empty() || number_of(c, v));
    t.header = options.csv.header.value_or(!all_numbers);
    columns_ = static_cast<int>(first.size());
    t.first_data = t.header ? 1 : 0;
    if (t.first_data >= rows.size()) reader_fail(path, "the file holds a header row and no data: not a recording", "not_a_recording");
    {
      const auto cells = split(rows[t.first_data], delimiter_);
      std::size_t numeric = 0;
      for (auto c : cells) numeric += number_of(c, v) ? 1 : 0;
      if (numeric == 0) {
        reader_fail(path, fmt::format("line {} holds no number: not a column file of samples", sample.lines[t.first_data]),
             "not_a_recording");
      }
    }
    t.names.resize(static_cast<std::size_t>(columns_));
    for (int c = 0; c < columns_; ++c) {
      t.names[static_cast<std::size_t>(c)] =
          t.header ? std::string(trim(first[static_cast<std::size_t>(c)])) : fmt::format("column {}", c);
    }
    // Columns that hold no samples: LabVIEW's Comment, or one left empty in every row (a trailing separator).
    t.skip.assign(static_cast<std::size_t>(columns_), false);
    for (int c = 0; c < columns_; ++c) {
      std::string lower = t.names[static_cast<std::size_t>(c)];
      std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
      bool empty = true;
      for (std::size_t r = t.first_data; r < rows.size(); ++r) {
        const auto cells = split(rows[r], delimiter_);
        if (static_cast<int>(cells.size()) > c && !trim(cells[static_cast<std::size_t>(c)]).empty()) empty = false;
      }
      t.skip[static_cast<std::size_t>(c)] = lower == "comment" || empty;
    }
    return t;
  }

  // The time column (stated, by name or by its values) and the data columns.
  void choose_time_column(const Sample& sample, const Table& t, const ReaderOptions& options) {
    const auto& names = t.names;
    const auto& skip = t.skip;
    time_column_ = options.csv.time_column;
    if (time_column_ >= columns_) {
      reader_fail(info_.path, fmt::format("time column {} does not exist: the file has {} columns", time_column_, columns_), "time-column");
    }
    if (time_column_ == -2) {
      time_column_ = -1;
      for (int c = 0; t.header && c < columns_ && time_column_ < 0; ++c) {
        if (!skip[static_cast<std::size_t>(c)] && is_time_name(names[static_cast<std::size_t>(c)])) time_column_ = c;
      }
      const int usable = static_cast<int>(std::count(skip.begin(), skip.end(), false));
      for (int c = 0; usable >= 3 && c < columns_ && time_column_ < 0; ++c) {
        if (!skip[static_cast<std::size_t>(c)] && evenly_increasing(sample.rows, t.first_data, c)) time_column_ = c;
      }
    }
    for (int c = 0; c < columns_; ++c) {
      if (c == time_column_ || skip[static_cast<std::size_t>(c)]) continue;
      // LabVIEW's one X column per channel: the other time columns are not data.
      if (time_column_ >= 0 && t.header && is_time_name(names[static_cast<std::size_t>(c)])) continue;
      data_columns_.push_back(c);
      info_.channel_names.push_back(names[static_cast<std::size_t>(c)]);
    }
    info_.channels = static_cast<int>(data_columns_.size());
    read_cells_ = std::max(time_column_, data_columns_.empty() ? -1 : data_columns_.back()) + 1;
    if (info_.channels <= 0) reader_fail(info_.path, "the file has no data column besides its time column", "not_a_recording");
  }

  // The sampling rate from Delta_X, the time column or the stated rate
  // (the data must already be located: the time column is read from there).
  double sampling_rate(const Table& t, const ReaderOptions& options, std::optional<double> lvm_delta) const {
    const fs::path& path = info_.path;
    // Forced, the stated rate sets the time column aside (time_base.hpp).
    const bool forced = options.override_fs && options.fs > 0.0;
    std::optional<TimeBaseRate> timed;
    std::string timed_where;
    if (time_column_ >= 0 && !forced) {
      const std::string& name = t.names[static_cast<std::size_t>(time_column_)];
      timed_where = fmt::format("its time column '{}'", name);
      timed = time_column_rate(name, time_unit(t.header ? name : std::string()));
    }
    if (lvm_delta) {
      if (timed && !agrees(*timed, 1.0 / *lvm_delta)) {
        reader_fail(path,
                    fmt::format("its Delta_X gives a sampling rate of {} but {} steps at {}: one of them is wrong; "
                                "correct the file, or force the rate",
                                format_quantity(1.0 / *lvm_delta, Dimension::frequency), timed_where,
                                format_quantity(timed->fs, Dimension::frequency)),
                    "override-fs");
      }
      return stated_rate(path, options, 1.0 / *lvm_delta, "its Delta_X");
    }
    if (timed) return stated_rate(path, options, timed->fs, timed_where, timed->tolerance);
    if (options.fs > 0.0) return options.fs;
    reader_fail(path, "the file has no time column; state the sampling rate, or name the time column", "fs");
  }

  // A row of the table: every column read is there. The columns after them
  // hold no samples (LabVIEW's Comment, a trailing separator): LabVIEW writes
  // rows with and without the empty Comment cell, so they may be left out, or
  // come as empty cells beyond the first row's.
  [[nodiscard]] bool fits(const std::vector<std::string_view>& cells) const {
    if (static_cast<int>(cells.size()) < read_cells_) return false;
    for (auto k = static_cast<std::size_t>(columns_); k < cells.size(); ++k) {
      if (!trim(cells[k]).empty()) return false;
    }
    return true;
  }

  // A number in the file's decimal convention.
  [[nodiscard]] bool number_of(std::string_view cell, double& value) const {
    if (decimal_ == '.') return parse_number(cell, value);
    std::string c(trim(cell));
    std::replace(c.begin(), c.end(), ',', '.');
    return parse_number(c, value);
  }

  // Seconds per unit of a time column named with a unit in brackets
  // ("Time [ms]", "t (us)"); 1 without one.
  double time_unit(const std::string& name) const {
    for (auto [open, close] : {std::pair{'[', ']'}, std::pair{'(', ')'}}) {
      const auto a = name.find(open), b = name.find(close);
      if (a == std::string::npos || b == std::string::npos || b <= a + 1) continue;
      try {
        return parse_quantity("1" + name.substr(a + 1, b - a - 1), Dimension::time);
      } catch (const std::invalid_argument&) {
        reader_fail(info_.path, fmt::format("the time column '{}' has a unit that is not a time", name), "time-column");
      }
    }
    return 1.0;
  }

  static bool is_time_name(std::string name) {
    // Without a unit in brackets, lower case: time, t, zeit, temps, tiempo, x_value, ...
    for (const char* open : {"[", "("}) {
      const auto at = name.find(open);
      if (at != std::string::npos && at > 0) name.resize(at);
    }
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
    name = std::string(trim(name));
    for (const char* known : {"time", "t", "zeit", "temps", "tiempo", "x_value", "time_s", "seconds", "s", "sec"}) {
      if (name == known) return true;
    }
    return false;
  }

  // Strictly increasing with a constant step (to 1e-6 of it) over the sampled rows.
  [[nodiscard]] bool evenly_increasing(const std::vector<std::string>& rows, std::size_t first, int column) const {
    std::vector<double> t;
    for (std::size_t r = first; r < rows.size(); ++r) {
      const auto cells = split(rows[r], delimiter_);
      double v;
      if (static_cast<int>(cells.size()) <= column || !number_of(cells[static_cast<std::size_t>(column)], v)) return false;
      t.push_back(v);
    }
    if (t.size() < 3) return false;
    const double step = t[1] - t[0];
    if (!(step > 0.0)) return false;
    for (std::size_t i = 1; i < t.size(); ++i) {
      if (std::fabs((t[i] - t[i - 1]) - step) > 1e-6 * std::fabs(step) + 1e-12 * std::fabs(t[i])) return false;
    }
    return true;
  }

  // The rate of the time column by the time-base rule (awcc/detail/time_base.hpp),
  // over its rows up to the first that is not a row of the table (read() refuses it).
  TimeBaseRate time_column_rate(const std::string& name, double unit) const {
    TimeBase base;
    base.path = info_.path;
    base.name = fmt::format("the time column '{}'", name);
    base.where = [this](std::uint64_t index) { return fmt::format("line {}", line_of_row(index)); };
    base.fix = "name the right time column, or state the sampling rate and force it";
    base.quantity = "time-column";
    base.scan = [&](const TimeBase::Sink& sink) {
      std::ifstream in(info_.path, std::ios::binary);
      in.seekg(data_start_);
      std::vector<double> block;
      std::uint64_t first = 0;
      double resolution = 0.0;
      std::string line, cell;
      std::int64_t number = first_line_;
      while (bounded_getline(in, line, info_.path, ++number)) {
        if (trim(line).empty()) continue;
        const auto cells = split(line, delimiter_);
        double t;
        if (!fits(cells) || !number_of(cells[static_cast<std::size_t>(time_column_)], t)) {
          break;
        }
        cell = trim(cells[static_cast<std::size_t>(time_column_)]);
        std::replace(cell.begin(), cell.end(), ',', '.');
        // The finest printed digit: a column printed to fixed decimals has one throughout.
        const double q = resolution_of_text(cell);
        if (q > 0.0 && (resolution == 0.0 || q < resolution)) resolution = q;
        block.push_back(t * unit);
        if (block.size() == 4096) {
          sink(first, block);
          first += block.size();
          block.clear();
        }
      }
      sink(first, block);
      return TimeBaseScan{first + block.size(), resolution * unit};
    };
    return time_base_rate(base);
  }

  // The line number of data row `row` (from 0; blank lines are no rows).
  [[nodiscard]] std::int64_t line_of_row(std::uint64_t row) const {
    std::ifstream in(info_.path, std::ios::binary);
    in.seekg(data_start_);
    std::string line;
    std::int64_t number = first_line_;
    std::uint64_t seen = 0;
    while (bounded_getline(in, line, info_.path, ++number)) {
      if (!trim(line).empty() && seen++ == row) break;
    }
    return number;
  }

  std::ifstream in_;
  bool lvm_ = false;
  LvmHeader first_segment_;  // a LabVIEW file's header up to its first data
  char delimiter_ = ',';
  char decimal_ = '.';
  int columns_ = 0;
  int read_cells_ = 0;  // a row holds at least the columns up to the last one read
  int time_column_ = -1;
  std::vector<int> data_columns_;
  std::streampos data_start_ = 0;
  std::int64_t line_ = 0, first_line_ = 0;
};

}  // namespace

bool looks_like_text(const fs::path& path) {
  const std::string head = leading_bytes(path, 512);
  return !head.empty() && std::none_of(head.begin(), head.end(), [](char ch) {
    const auto c = static_cast<unsigned char>(ch);
    return c == 0 || (c < 32 && c != '\n' && c != '\r' && c != '\t');
  });
}

std::unique_ptr<Recording> open_csv(const fs::path& path, const ReaderOptions& options) {
  return std::make_unique<CsvRecording>(path, options);
}

}  // namespace awcc::detail
