#pragma once
// InputError: bad user input (scene field, command-line value, input file). The CLI turns it
// into exit code 2; the message always names the field, the value and what is allowed.
#include <stdexcept>
#include <string>

namespace sb {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace sb
