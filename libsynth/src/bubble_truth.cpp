#include "synth/bubble_truth.hpp"

#include <charconv>
#include <fmt/format.h>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>

#include "awcc/atomic_output.hpp"
#include "awcc/csv.hpp"
#include "awcc/errors.hpp"

namespace synth {
namespace {

// Truth is written exactly (shortest text that reads back to the same
// value), not to csv_number's 10 digits: 10 digits of a time near 300 s are
// 0.1 us, a twentieth of a sample at 500 kHz, and the truth must not carry
// an error of its own into a comparison.
void put(std::string& out, double v) {
  if (!std::isnan(v)) fmt::format_to(std::back_inserter(out), "{}", v);
}
void put(std::string& out, float v) {
  if (!std::isnan(v)) fmt::format_to(std::back_inserter(out), "{}", v);
}

// A cell as a number of type T; an empty cell is NaN where `may_be_empty`.
// Throws std::invalid_argument saying what is wrong with it.
template <class T>
T number(std::string_view cell, bool may_be_empty) {
  if (cell.empty()) {
    if (may_be_empty) return std::numeric_limits<T>::quiet_NaN();
    throw std::invalid_argument("the cell is empty; it must hold a number");
  }
  T v{};
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  if (ec != std::errc{} || end != cell.data() + cell.size() || !std::isfinite(v))
    throw std::invalid_argument(fmt::format("'{}' is not a finite number", cell));
  return v;
}

template <class T>
T whole(std::string_view cell) {
  T v{};
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  if (cell.empty() || ec != std::errc{} || end != cell.data() + cell.size())
    throw std::invalid_argument(fmt::format("'{}' is not a whole number", cell));
  return v;
}

// The columns, declared once: name, unit (docs/output.md), and how a cell
// is written from and read into a row. The reader appends a default row
// first, so each read sets one value.
struct BubbleColumn {
  std::string_view name;
  std::string_view unit;
  void (*write)(std::string&, const BubbleTruth&, std::size_t row);
  void (*read)(BubbleTruth&, std::size_t row, std::string_view cell);
};

struct TipColumn {
  std::string_view name;
  std::string_view unit;
  void (*write)(std::string&, const TipPierce&);
  void (*read)(TipPierce&, std::string_view cell);  // null: the pierced column, checked against front
};

#define PDP_BUBBLE_NUMBER(NAME, UNIT, EXPR)                                                        \
  BubbleColumn {                                                                                   \
    NAME, UNIT, [](std::string& o, const BubbleTruth& t, std::size_t r) { put(o, t.EXPR); },       \
        [](BubbleTruth& t, std::size_t r, std::string_view c) { t.EXPR = number<double>(c, false); } \
  }
#define PDP_TIP_NUMBER(NAME, UNIT, MEMBER, TYPE)                                                   \
  TipColumn {                                                                                      \
    NAME, UNIT, [](std::string& o, const TipPierce& p) { put(o, p.MEMBER); },                      \
        [](TipPierce& p, std::string_view c) { p.MEMBER = number<TYPE>(c, true); }                 \
  }

const BubbleColumn kBubbleColumns[] = {
    {"id", "-", [](std::string& o, const BubbleTruth& t, std::size_t r) { fmt::format_to(std::back_inserter(o), "{}", t.id[r]); },
     [](BubbleTruth& t, std::size_t r, std::string_view c) { t.id[r] = whole<std::uint64_t>(c); }},
    PDP_BUBBLE_NUMBER("diameter", "m", diameter[r]),
    PDP_BUBBLE_NUMBER("semi_axis_x", "m", semi_axes[r].x),
    PDP_BUBBLE_NUMBER("semi_axis_y", "m", semi_axes[r].y),
    PDP_BUBBLE_NUMBER("semi_axis_z", "m", semi_axes[r].z),
    PDP_BUBBLE_NUMBER("velocity_x", "m/s", velocity[r].x),
    PDP_BUBBLE_NUMBER("velocity_y", "m/s", velocity[r].y),
    PDP_BUBBLE_NUMBER("velocity_z", "m/s", velocity[r].z),
    PDP_BUBBLE_NUMBER("interaction_start", "s", interaction_start[r]),
    PDP_BUBBLE_NUMBER("interaction_end", "s", interaction_end[r]),
    {"extra_passes", "-",
     [](std::string& o, const BubbleTruth& t, std::size_t r) { fmt::format_to(std::back_inserter(o), "{}", t.extra_passes[r]); },
     [](BubbleTruth& t, std::size_t r, std::string_view c) { t.extra_passes[r] = whole<std::int32_t>(c); }},
};

const TipColumn kTipColumns[] = {
    {"pierced", "0/1", [](std::string& o, const TipPierce& p) { o += p.pierced() ? '1' : '0'; }, nullptr},
    PDP_TIP_NUMBER("front", "s", front, double),
    PDP_TIP_NUMBER("rear", "s", rear, double),
    PDP_TIP_NUMBER("chord", "m", chord, double),
    PDP_TIP_NUMBER("front_normal_x", "-", front_normal[0], float),
    PDP_TIP_NUMBER("front_normal_y", "-", front_normal[1], float),
    PDP_TIP_NUMBER("front_normal_z", "-", front_normal[2], float),
    PDP_TIP_NUMBER("rear_normal_x", "-", rear_normal[0], float),
    PDP_TIP_NUMBER("rear_normal_y", "-", rear_normal[1], float),
    PDP_TIP_NUMBER("rear_normal_z", "-", rear_normal[2], float),
};

#undef PDP_BUBBLE_NUMBER
#undef PDP_TIP_NUMBER

constexpr std::size_t kBubbleCount = std::size(kBubbleColumns);
constexpr std::size_t kTipCount = std::size(kTipColumns);

std::string tip_column(std::size_t tip, std::string_view name) { return fmt::format("tip{}_{}", tip, name); }

void append_default_row(BubbleTruth& t) {
  t.id.push_back(0);
  t.diameter.push_back(0.0);
  t.semi_axes.push_back({});
  t.velocity.push_back({});
  t.interaction_start.push_back(0.0);
  t.interaction_end.push_back(0.0);
  t.extra_passes.push_back(0);
  t.pierces.resize(t.pierces.size() + t.tip_count);
}

}  // namespace

std::vector<std::string> bubble_truth_columns(std::size_t tip_count) {
  std::vector<std::string> out;
  for (const auto& c : kBubbleColumns) out.emplace_back(c.name);
  for (std::size_t k = 0; k < tip_count; ++k)
    for (const auto& c : kTipColumns) out.push_back(tip_column(k, c.name));
  return out;
}

void write_bubble_truth_csv(const std::filesystem::path& path, const BubbleTruth& table) {
  awcc::write_atomically(path, [&](const std::filesystem::path& temporary) {
    std::ofstream out(temporary, std::ios::binary);
    if (!out) throw awcc::OutputError(fmt::format("{}: cannot open the bubble truth table for writing", path.string()));
    std::string line;
    for (const auto& name : bubble_truth_columns(table.tip_count)) line += (line.empty() ? "" : ",") + awcc::csv_cell(name);
    out << line << '\n';
    for (std::size_t r = 0; r < table.size(); ++r) {
      line.clear();
      for (std::size_t i = 0; i < kBubbleCount; ++i) {
        if (i) line += ',';
        kBubbleColumns[i].write(line, table, r);
      }
      for (std::size_t k = 0; k < table.tip_count; ++k) {
        for (const auto& c : kTipColumns) {
          line += ',';
          c.write(line, table.pierce(r, k));
        }
      }
      line += '\n';
      out << line;
    }
    out.flush();
    if (!out) throw awcc::OutputError(fmt::format("{}: writing the bubble truth table failed (disk full?)", path.string()));
  });
}

BubbleTruth read_bubble_truth_csv(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw awcc::InputError(fmt::format("{}: cannot open the bubble truth table", path.string()));
  std::string line;
  if (!std::getline(in, line))
    throw awcc::InputError(fmt::format("{}: empty file; a bubble truth table starts with its header", path.string()));
  const auto header = awcc::split_cells(line);
  if (header.size() < kBubbleCount || (header.size() - kBubbleCount) % kTipCount != 0)
    throw awcc::InputError(fmt::format("{}: line 1: {} columns; a bubble truth table has {} and {} for each tip "
                                       "(pdp synth writes it with bubble-truth on)",
                                       path.string(), header.size(), kBubbleCount, kTipCount));
  BubbleTruth t;
  t.tip_count = (header.size() - kBubbleCount) / kTipCount;
  const auto expected = bubble_truth_columns(t.tip_count);
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] != expected[i])
      throw awcc::InputError(fmt::format("{}: line 1: column {} is '{}' where a bubble truth table has '{}'",
                                         path.string(), i + 1, header[i], expected[i]));
  }
  std::size_t line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const auto cells = awcc::split_cells(line);
    if (cells.size() != header.size())
      throw awcc::InputError(fmt::format("{}: line {}: {} cells where the header has {} columns", path.string(),
                                         line_number, cells.size(), header.size()));
    const std::size_t r = t.size();
    append_default_row(t);
    std::size_t i = 0;
    try {
      for (; i < kBubbleCount; ++i) kBubbleColumns[i].read(t, r, cells[i]);
      for (std::size_t k = 0; k < t.tip_count; ++k) {
        const std::size_t first = i;
        TipPierce& p = t.pierce(r, k);
        for (const auto& c : kTipColumns) {
          if (c.read) c.read(p, cells[i]);
          ++i;
        }
        i = first;  // the pierced cell, against the front read after it
        if (cells[i] != (p.pierced() ? "1" : "0"))
          throw std::invalid_argument(fmt::format("'{}' disagrees with the front time ({}): write 1 when it has one, "
                                                  "0 when it is empty",
                                                  cells[i], p.pierced() ? "given" : "empty"));
        i = first + kTipCount;
      }
    } catch (const std::invalid_argument& e) {
      throw awcc::InputError(
          fmt::format("{}: line {}: column {}: {}", path.string(), line_number, expected[i], e.what()), expected[i]);
    }
  }
  return t;
}

}  // namespace synth
