#include "correction/sweep_columns.hpp"

#include <initializer_list>

namespace correction {

namespace {

// The value whose written text is `text`, of the values an enum column takes.
template <class E>
std::optional<E> value_named(std::string_view text, std::initializer_list<E> values) {
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
  return value_named(text, {awcc::Weighting::duration, awcc::Weighting::none});
}

std::optional<awcc::CorrelationSignal> signal_of(std::string_view text) {
  return value_named(text, {awcc::CorrelationSignal::binary, awcc::CorrelationSignal::raw});
}

std::optional<awcc::Subsample> subsample_of(std::string_view text) {
  return value_named(text, {awcc::Subsample::none, awcc::Subsample::parabolic});
}

}  // namespace correction
