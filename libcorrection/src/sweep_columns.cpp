#include "correction/sweep_columns.hpp"

#include <span>

#include "awcc/read_back.hpp"

namespace correction {

namespace {

// The value whose written text is `text`, of the values an enum column takes
// (awcc::values: the one list of each enum's values).
template <class E>
std::optional<E> value_named(std::string_view text, std::span<const E> values) {
  for (E v : values)
    if (awcc::to_string(v) == text) return v;
  return std::nullopt;
}

}  // namespace

std::string sweep_csv_header(const std::vector<std::string>& scene_columns) {
  std::string h;
  for (const auto& c : sweep_key_columns) h += (h.empty() ? "" : ",") + std::string(c.name);
  for (const auto& c : scene_columns) h += "," + c;
  for (const auto& c : sweep_result_columns) h += "," + std::string(c.name);
  return h;
}

std::string_view roc_text(bool roc) { return roc ? "on" : "off"; }

std::optional<bool> roc_of(std::string_view text) {
  if (text == roc_text(true)) return true;
  if (text == roc_text(false)) return false;
  return std::nullopt;
}

std::optional<awcc::Weighting> weighting_of(std::string_view text) {
  return value_named<awcc::Weighting>(text, awcc::values::weighting);
}

std::optional<awcc::CorrelationSignal> signal_of(std::string_view text) {
  return value_named<awcc::CorrelationSignal>(text, awcc::values::signal);
}

std::optional<awcc::Subsample> subsample_of(std::string_view text) {
  return value_named<awcc::Subsample>(text, awcc::values::subsample);
}

}  // namespace correction
