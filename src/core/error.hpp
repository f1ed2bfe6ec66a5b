// The one exception type of Terrapolis; only main() turns it into an exit code.
// SPDX-License-Identifier: MIT
#pragma once
#include <stdexcept>
#include <string>

namespace terrapolis {

enum class ErrorKind {
  bad_input,   ///< the user's file, option or scenario is wrong: exit code 2
  processing,  ///< the work itself failed (I/O during processing, numerical failure): exit code 1
  cancelled,   ///< the progress sink asked to stop: exit code 1
};

/// An error whose message names the file, field or stage and the problem, on one line.
class Error : public std::runtime_error {
 public:
  Error(ErrorKind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  ErrorKind kind() const noexcept { return kind_; }
  int exit_code() const noexcept { return kind_ == ErrorKind::bad_input ? 2 : 1; }

 private:
  ErrorKind kind_;
};

inline Error bad_input(const std::string& message) { return Error(ErrorKind::bad_input, message); }
inline Error processing_error(const std::string& message) { return Error(ErrorKind::processing, message); }

}  // namespace terrapolis
