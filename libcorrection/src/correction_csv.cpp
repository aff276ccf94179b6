// The corrections' CSV columns (correction_csv_columns): one owner of their
// names, units and cells.

#include "correction/model.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <deque>
#include <fstream>
#include <iterator>

#include <cerrno>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <stdexcept>
#include <zlib.h>

#include "awcc/atomic_output.hpp"
#include "awcc/awcc.hpp"
#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/read_back.hpp"
#include "correction/modality.hpp"

namespace correction {

std::span<const awcc::ProfileColumn> correction_csv_columns() {
  // Built once from the levels; the strings live as long as the program.
  static const auto columns = [] {
    static std::deque<std::string> text;
    auto keep = [](std::string s) -> std::string_view { return text.emplace_back(std::move(s)); };
    std::vector<awcc::ProfileColumn> out{
        {"correction_in_range", "", "/correction/in_range", "1 when the row was corrected"},
        {"correction_reason", "", "/correction/reason",
         "why the row was not corrected (untrusted: which trust rule its quantiles break, with the numbers)"},
        {correction_column::forest, "", "/correction/forest",
         "the forest that gave the quantiles: awcc, or fscc (velocity only)"}};
    for (const char* q : {"velocity", "turbulence_intensity"}) {
      const bool u = std::string_view(q) == "velocity";
      const char* unit = u ? "m/s" : "-";
      const char* what = u ? "velocity" : "turbulence intensity";
      out.push_back({keep(fmt::format("corrected_{}", q)), unit, keep(fmt::format("/correction/{}/median", q)),
                     keep(fmt::format("corrected {} (median of the truth given the measurement; empty when not "
                                      "corrected, untrusted included)",
                                      what))});
      for (const char* l : correction_level_names) {
        out.push_back({keep(fmt::format("corrected_{}_q{}", q, l)), unit,
                       keep(fmt::format("/correction/{}/quantiles/{}", q, l)),
                       keep(fmt::format("quantile {} of the true {} (of an untrusted row too: not a corrected value)",
                                        l, what))});
      }
    }
    out.push_back({correction_column::status, "", "/correction/status", "corrected, untrusted, or why not"});
    out.push_back({"correction_notes", "", "/correction/notes",
                   "what to know of the correction (a record longer than the training records, held at their "
                   "length), joined by '; '"});
    out.push_back({correction_column::turbulence_reason, "", "/correction/turbulence_intensity/reason",
                   "why the corrected Tu is empty on a row whose velocity stands (trust rule (e): bubbles far larger "
                   "than the tip separation); empty otherwise"});
    return out;
  }();
  return columns;
}

std::string correction_csv_header() {
  std::string out;
  for (const auto& c : correction_csv_columns()) out += (out.empty() ? "" : ",") + std::string(c.name);
  return out;
}

std::string quantile_cells(const Correction& c) {
  std::string out;
  for (const auto* q : {&c.velocity, &c.turbulence_intensity}) {
    if (*q) {
      // An untrusted row's median is not a corrected value: its quantiles
      // only; nor is a Tu that rule (e) leaves uncorrected.
      const bool stands = q == &c.velocity ? c.corrected() : c.turbulence_corrected();
      out += stands ? fmt::format(",{:.10g}", (*q)->median()) : ",";
      for (double v : (*q)->quantiles) out += fmt::format(",{:.10g}", v);
    } else {
      out += std::string(1 + correction_levels.size(), ',');
    }
  }
  return out;
}

std::string notes_text(const Correction& c) {
  std::string notes;
  for (const auto& n : c.notes) notes += (notes.empty() ? "" : "; ") + n;
  return notes;
}

std::string correction_csv_cells(const Correction& c) {
  return fmt::format("{},{},{}{},{},{},{}", c.corrected() ? 1 : 0,
                     awcc::csv_cell(c.corrected() ? std::string() : c.message), c.forest, quantile_cells(c),
                     to_string(c.status), awcc::csv_cell(notes_text(c)), awcc::csv_cell(c.turbulence_message));
}

nlohmann::json to_json(const Correction& c) {
  using nlohmann::json;
  // An untrusted row's median is not a corrected value: null, its quantiles kept.
  // So is a Tu that rule (e) leaves uncorrected, its reason given.
  auto quantity = [](const std::optional<CorrectedQuantity>& q, bool stands) {
    if (!q) return json(nullptr);
    json levels = json::object();
    for (std::size_t k = 0; k < correction_levels.size(); ++k) levels[correction_level_names[k]] = q->quantiles[k];
    return json{{"measured", q->measured}, {"median", stands ? json(q->median()) : json(nullptr)},
                {correction_key::quantiles, levels}};
  };
  json tu = quantity(c.turbulence_intensity, c.turbulence_corrected());
  if (tu.is_object()) {
    tu[correction_key::reason] = c.turbulence_message.empty() ? json(nullptr) : json(c.turbulence_message);
  }
  return json{{correction_key::status, to_string(c.status)},
              {"in_range", c.corrected()},
              {correction_key::forest, c.forest.empty() ? json(nullptr) : json(c.forest)},
              {"reason", c.corrected() ? json(nullptr) : json(c.message)},
              {"notes", c.notes},
              {correction_key::velocity, quantity(c.velocity, c.corrected())},
              {correction_key::turbulence_intensity, tu}};
}

}  // namespace correction
