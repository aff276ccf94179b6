#include "correct_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "awcc/atomic_output.hpp"
#include "awcc/correction.hpp"
#include "awcc/units.hpp"
#include "cells.hpp"

namespace pdp {

CLI::App* setup_correct(CLI::App& app, CorrectOptions& o) {
  auto* cmd = app.add_subcommand("correct", "Add bias-corrected velocity and Tu quantiles to a pdp process JSON or profile CSV");
  cmd->set_config("--config", "", "TOML file of these options");
  cmd->add_option("input", o.input, "pdp process JSON (one recording or a profile) or profile CSV")
      ->required()->check(CLI::ExistingFile);
  cmd->add_option("-m,--model", o.model, "correction model (.qrf, from pdp train; samples/model/awcc.qrf ships)")
      ->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o.output, "output file (same format as the input) [default: stdout]");
  cmd->add_option("--dx", o.dx, "streamwise tip separation, m (units allowed), where the input has none");
  cmd->add_option("--dy", o.dy, "lateral tip separation, m (units allowed), where the input has none");
  cmd->add_option("--np", o.np, "AWCC particles per window, where the input has none")->check(CLI::Range(1, 1000));
  return cmd;
}

namespace {

struct Fallbacks {
  std::optional<double> dx, dy, np;
};

// What a row lacks and no option gives is an error naming the file, the
// field and the fix.
double need(const std::optional<double>& from_file, const std::optional<double>& from_option, const std::string& file,
            const char* field, const char* option) {
  if (from_file) return *from_file;
  if (from_option) return *from_option;
  throw std::invalid_argument(fmt::format("{}: no {} in the file; give it with {}", file, field, option));
}

awcc::Correction correct_json_row(const awcc::CorrectionModel& model, const nlohmann::json& r, const Fallbacks& fb,
                                  const std::string& file) {
  using nlohmann::json;
  auto number = [](const json& j, const char* key) -> std::optional<double> {
    if (!j.is_object() || !j.contains(key) || !j[key].is_number()) return std::nullopt;
    return j[key].get<double>();
  };
  if (!r.contains("awcc") || !r["awcc"].is_object()) return awcc::not_corrected("AWCC was not run (pdp process --method awcc or both)");
  const auto& a = r["awcc"];
  if (!a.value("defined", false)) {
    return awcc::not_corrected("AWCC gave no velocity: " + (a.contains("reason") && a["reason"].is_string() ? a["reason"].get<std::string>() : std::string()));
  }
  if (!r.contains("tips") || !r["tips"].is_array() || r["tips"].empty()) {
    throw std::invalid_argument(fmt::format("{}: a result without 'tips'; give a JSON written by pdp process", file));
  }
  const auto& lead = r["tips"][0];
  awcc::CorrectionFeatures f;
  auto required = [&](const json& j, const char* key, const char* where) {
    const auto v = number(j, key);
    if (!v) throw std::invalid_argument(fmt::format("{}: no number '{}' in {}; give a JSON written by pdp process", file, key, where));
    return *v;
  };
  f.velocity = required(a, "velocity", "awcc");
  f.turbulence_intensity = required(a, "turbulence_intensity", "awcc");
  f.windows_accepted = static_cast<std::int64_t>(required(a, "windows_accepted", "awcc"));
  f.void_fraction = required(lead, "void_fraction", "tips[0]");
  const double count_rate = required(lead, "bubble_count_rate", "tips[0]");
  if (!(count_rate > 0.0)) return awcc::not_corrected("no bubbles on the leading tip");
  f.d32 = 1.5 * f.velocity * f.void_fraction / count_rate;
  f.dx = need(number(r, "dx"), fb.dx, file, "dx", "--dx");
  f.dy = need(number(r, "dy"), fb.dy, file, "dy", "--dy");
  f.np = need(number(a, "np"), fb.np, file, "awcc.np", "--np");
  return model.correct(f);
}

std::string correct_json(const awcc::CorrectionModel& model, const std::string& text, const Fallbacks& fb,
                         const std::string& file, const std::string& model_name) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw std::invalid_argument(fmt::format("{}: not valid JSON ({}); give a pdp process JSON or profile CSV", file, e.what()));
  }
  auto add = [&](nlohmann::json& row) {
    auto c = awcc::to_json(correct_json_row(model, row, fb, file));
    c["model"] = model_name;
    row["correction"] = c;
  };
  if (j.is_object() && j.contains("profile") && j["profile"].is_array()) {
    for (auto& row : j["profile"]) add(row);
  } else if (j.is_object() && j.contains("tips")) {
    add(j);
  } else {
    throw std::invalid_argument(fmt::format("{}: neither a recording's result (tips) nor a profile; give a JSON written by pdp process", file));
  }
  return j.dump(2) + "\n";
}

std::string correct_csv(const awcc::CorrectionModel& model, const std::string& text, const Fallbacks& fb,
                        const std::string& file) {
  std::stringstream in(text);
  std::string line;
  if (!std::getline(in, line)) throw std::invalid_argument(fmt::format("{}: empty file", file));
  if (!line.empty() && line.back() == '\r') line.pop_back();
  const auto header = split_cells(line);
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < header.size(); ++i) col[header[i]] = i;
  for (const char* name : {"void_fraction", "bubble_count_rate", "awcc_velocity", "awcc_turbulence_intensity", "awcc_windows_accepted"}) {
    if (!col.count(name)) {
      throw std::invalid_argument(fmt::format("{}: no column '{}'; give a profile CSV of pdp process --method awcc or both "
                                              "(docs/output.md)", file, name));
    }
  }
  if (col.count("correction_in_range")) throw std::invalid_argument(fmt::format("{}: already corrected (correction columns present)", file));
  std::string out = line + "," + awcc::correction_csv_header() + "\n";
  int number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const auto cells = split_cells(line);
    if (cells.size() != header.size()) {
      throw std::invalid_argument(fmt::format("{}:{}: {} cells where the header has {}", file, number, cells.size(), header.size()));
    }
    auto value = [&](const char* name) -> std::optional<double> {
      const auto it = col.find(name);
      if (it == col.end() || cells[it->second].empty()) return std::nullopt;
      const auto v = cell_number(cells[it->second]);
      if (!v) throw std::invalid_argument(fmt::format("{}:{}: column {} = '{}' is not a number", file, number, name, cells[it->second]));
      return v;
    };
    awcc::Correction c;
    const auto u = value("awcc_velocity"), tu = value("awcc_turbulence_intensity");
    const auto c_lead = value("void_fraction"), f_lead = value("bubble_count_rate");
    if (!u || !tu) {
      c = awcc::not_corrected("AWCC gave no velocity");
    } else if (!f_lead || !(*f_lead > 0.0) || !c_lead) {
      c = awcc::not_corrected("no bubbles on the leading tip");
    } else {
      awcc::CorrectionFeatures f;
      f.velocity = *u;
      f.turbulence_intensity = *tu;
      f.void_fraction = *c_lead;
      f.d32 = 1.5 * *u * *c_lead / *f_lead;
      const std::string where = fmt::format("{}:{}", file, number);
      f.dx = need(value("dx"), fb.dx, where, "dx column", "--dx");
      f.dy = need(value("dy"), fb.dy, where, "dy column", "--dy");
      f.np = need(value("np"), fb.np, where, "np column", "--np");
      f.windows_accepted = static_cast<std::int64_t>(value("awcc_windows_accepted").value_or(0.0));
      c = model.correct(f);
    }
    out += line + "," + awcc::correction_csv_cells(c) + "\n";
  }
  return out;
}

}  // namespace

int run_correct(const CorrectOptions& o) {
  Fallbacks fb;
  try {
    if (!o.dx.empty()) fb.dx = awcc::parse_quantity(o.dx, awcc::Dimension::length);
    if (!o.dy.empty()) fb.dy = awcc::parse_quantity(o.dy, awcc::Dimension::length);
    if (o.np > 0) fb.np = o.np;
    if (!o.output.empty() && std::filesystem::exists(o.output) &&
        (std::filesystem::equivalent(o.output, o.input) || std::filesystem::equivalent(o.output, o.model))) {
      throw std::invalid_argument(fmt::format("{} is an input; choose another output file", o.output));
    }
  } catch (const std::invalid_argument& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
  try {
    const auto model = awcc::CorrectionModel::load(o.model);
    std::ifstream in(o.input, std::ios::binary);
    std::stringstream buffer;
    buffer << in.rdbuf();
    const std::string text = buffer.str();
    const auto first = text.find_first_not_of(" \t\r\n");
    const bool json = first != std::string::npos && (text[first] == '{' || text[first] == '[');
    const std::string model_name = std::filesystem::path(o.model).filename().string();
    const std::string out = json ? correct_json(model, text, fb, o.input, model_name) : correct_csv(model, text, fb, o.input);
    if (o.output.empty()) fmt::print("{}", out);
    else awcc::write_text_atomically(o.output, out);
  } catch (const std::invalid_argument& e) {
    spdlog::error("{}", e.what());
    return 2;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}

}  // namespace pdp
