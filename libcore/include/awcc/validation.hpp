#pragma once
// What every options struct's validate() returns (Ceres's Options::IsValid,
// as a value): ok, or what is wrong with its fix and the declared name of
// the option that fixes it (OptionField::name, as OptionError::quantity()),
// so that a front end names its own flag or keyword for it.

#include <string>
#include <utility>

#include "awcc/errors.hpp"

namespace awcc {

enum class ValidationStatus {
  ok,
  invalid,      ///< a value or a combination that cannot work
  implausible,  ///< outside the plausible range of the instrument: nearly always a unit slip
};

struct Validation {
  ValidationStatus status = ValidationStatus::ok;
  std::string message;   ///< what is wrong and the fix; empty when ok
  std::string quantity;  ///< the declared name of the option that fixes it; empty when no single option does

  static Validation invalid(std::string quantity, std::string message) {
    return {ValidationStatus::invalid, std::move(message), std::move(quantity)};
  }
  static Validation implausible(std::string quantity, std::string message) {
    return {ValidationStatus::implausible, std::move(message), std::move(quantity)};
  }
  [[nodiscard]] bool ok() const { return status == ValidationStatus::ok; }
  /// Throws OptionError(message, quantity) unless ok.
  void throw_if_failed() const {
    if (!ok()) throw OptionError(message, quantity);
  }
};

}  // namespace awcc
