#pragma once
// The kinds of failure every part of the toolkit reports, so that callers
// (the pdp command line, the Python module) branch on the kind, never on the
// message text:
//  - std::invalid_argument (OptionError when the quantity is known): an option
//    or parameter is wrong or missing (a bad value, a combination that cannot
//    work). The message names the option by its declared name
//    (awcc/option_field.hpp), never by a command-line flag.
//  - InputError: input data cannot be used (a recording, a model file, a
//    results file): the message names the file, what is wrong, where, and the
//    fix.
//  quantity() is the declared name of the option that would fix the problem
//  ("fs", "filter-a", "allow-unusual"), several comma-separated when it
//  takes more than one ("leading-channel,trailing-channel"), or empty: a
//  front end names its own flag (--fs) or keyword (fs=) for it.
//  - OutputError: an output cannot be written.
// Anything else escaping the libraries is a defect.

#include <stdexcept>
#include <string>

namespace awcc {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message, std::string quantity = {})
      : std::runtime_error(message), quantity_(std::move(quantity)) {}
  /// The setting whose value would fix the problem; empty when none does.
  [[nodiscard]] const std::string& quantity() const { return quantity_; }

 private:
  std::string quantity_;
};

/// An option or parameter that is wrong or missing; quantity() as above.
class OptionError : public std::invalid_argument {
 public:
  explicit OptionError(const std::string& message, std::string quantity = {})
      : std::invalid_argument(message), quantity_(std::move(quantity)) {}
  [[nodiscard]] const std::string& quantity() const { return quantity_; }

 private:
  std::string quantity_;
};

class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace awcc
