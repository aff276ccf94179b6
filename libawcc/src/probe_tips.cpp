#include "awcc/probe_tips.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "awcc/errors.hpp"
#include "awcc/units.hpp"

namespace awcc {

namespace {

std::string point_text(const std::array<double, 3>& p) {
  return fmt::format("({}, {}, {})", format_quantity(p[0], Dimension::length), format_quantity(p[1], Dimension::length),
                     format_quantity(p[2], Dimension::length));
}

std::array<double, 3> minus(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

double distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  const auto d = minus(a, b);
  return std::hypot(d[0], d[1], d[2]);
}

}  // namespace

std::string tips_problem(const std::vector<std::array<double, 3>>& positions) {
  if (positions.size() == 1) {
    return fmt::format("one tip is declared, at {}; a probe has two or more tips: declare each tip's position",
                       point_text(positions[0]));
  }
  for (std::size_t j = 1; j < positions.size(); ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      if (distance(positions[i], positions[j]) < same_point_tolerance) {
        return fmt::format("tips {} and {} are both at {} (tips are numbered from 0): a tip listed twice; "
                           "correct the position of one of them",
                           i, j, point_text(positions[i]));
      }
    }
  }
  return {};
}

std::string channels_problem(const std::vector<int>& channels) {
  for (std::size_t j = 0; j < channels.size(); ++j) {
    if (channels[j] < 0) return fmt::format("tip {} is mapped to channel {}; channels are numbered from 0", j, channels[j]);
    for (std::size_t i = 0; i < j; ++i) {
      if (channels[i] == channels[j]) {
        return fmt::format("tips {} and {} are both mapped to channel {}: each tip has its own channel; correct "
                           "one of them",
                           i, j, channels[j]);
      }
    }
  }
  return {};
}

int ProbeTips::channel_of(std::size_t tip) const {
  return channels.empty() ? static_cast<int>(tip) : channels[tip];
}

Validation ProbeTips::validate() const {
  if (auto why = tips_problem(positions); !why.empty()) return Validation::invalid("tips", std::move(why));
  if (auto why = channels_problem(channels); !why.empty()) return Validation::invalid("tip-channels", std::move(why));
  if (!declared()) {
    if (leading != 0 || !channels.empty()) {
      return Validation::invalid("tips", "leading-tip and tip-channels describe declared tips: declare the tips' "
                                         "positions too");
    }
    return {};
  }
  if (leading < 0 || static_cast<std::size_t>(leading) >= positions.size()) {
    return Validation::invalid("leading-tip", fmt::format("the leading tip is tip {}, but {} tips are declared "
                                                          "(numbered from 0 to {})",
                                                          leading, positions.size(), positions.size() - 1));
  }
  if (!channels.empty() && channels.size() != positions.size()) {
    return Validation::invalid("tip-channels",
                               fmt::format("{} channels are given for {} tips: give one channel per tip, in the "
                                           "order of the tips",
                                           channels.size(), positions.size()));
  }
  return {};
}

ProbeTips probe_of(const ProbeTips& declared, const RecordingInfo& info) {
  const std::string file = info.path.string();
  if (!declared.declared()) {
    if (info.tip_positions.empty()) return {};
    return {info.tip_positions, info.leading_tip, {}};
  }
  const auto n = declared.positions.size();
  if (declared.channels.empty() && n > static_cast<std::size_t>(info.channels)) {
    throw InputError(fmt::format("{}: {} tips are declared but the recording holds {} channel{}: tip {} has no "
                                 "channel; record every tip, or declare only the tips recorded",
                                 file, n, info.channels, info.channels == 1 ? "" : "s", info.channels),
                     "tips");
  }
  for (std::size_t k = 0; k < declared.channels.size(); ++k) {
    if (declared.channels[k] >= info.channels) {
      throw InputError(fmt::format("{}: tip {} is mapped to channel {}, but the recording holds {} channel{} "
                                   "(numbered from 0): correct its channel",
                                   file, k, declared.channels[k], info.channels, info.channels == 1 ? "" : "s"),
                       "tip-channels");
    }
  }
  if (info.tip_positions.empty()) return declared;
  // The file states its tips too: both must describe one probe. Only the
  // separations from the leading tip are compared (each may have its own origin).
  const auto lead = static_cast<std::size_t>(declared.leading);
  const auto recorded_lead = static_cast<std::size_t>(declared.channel_of(lead));
  if (recorded_lead != static_cast<std::size_t>(info.leading_tip)) {
    throw InputError(fmt::format("{}: the declared leading tip is on channel {}, but the file states channel {} is "
                                 "the leading tip: correct leading-tip, or remove the declared tips to use the file's",
                                 file, recorded_lead, info.leading_tip),
                     "leading-tip");
  }
  for (std::size_t k = 0; k < n; ++k) {
    const auto c = static_cast<std::size_t>(declared.channel_of(k));
    const auto stated = minus(info.tip_positions[c], info.tip_positions[recorded_lead]);
    const auto given = minus(declared.positions[k], declared.positions[lead]);
    if (distance(stated, given) > separation_tolerance) {
      throw InputError(
          fmt::format("{}: tip {} (channel {}{}) is {} from the leading tip as declared (tips), but {} as the file "
                      "states: one of them is wrong; correct the declaration, or remove it to use the file's",
                      file, k, c, c < info.sensor_ids.size() ? fmt::format(", sensor {}", info.sensor_ids[c]) : "",
                      point_text(given), point_text(stated)),
          "tips");
    }
  }
  if (n != info.tip_positions.size()) {
    throw InputError(fmt::format("{}: {} tips are declared, but the file states the positions of {}: declare every "
                                 "tip the file holds, or remove the declaration to use the file's",
                                 file, n, info.tip_positions.size()),
                     "tips");
  }
  return declared;
}

}  // namespace awcc
