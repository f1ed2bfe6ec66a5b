// Console and JSON progress sinks, and the log.
// SPDX-License-Identifier: MIT
#include "core/progress.hpp"

#include <algorithm>
#include <cstdio>

#include "core/error.hpp"
#include "core/interrupt.hpp"

namespace terrapolis {

void ConsoleProgress::begin(std::string_view step) {
  std::fprintf(stderr, "%.*s: ", int(step.size()), step.data());
  printed_ = -1;
  update(0.0);
}

bool ConsoleProgress::update(double fraction) {
  const int tick = int(std::clamp(fraction, 0.0, 1.0) * 40.0 + 1e-9);
  while (printed_ < tick) {
    ++printed_;
    if (printed_ % 4 == 0) std::fprintf(stderr, "%d", printed_ / 4 * 10);
    else std::fputc('.', stderr);
  }
  std::fflush(stderr);
  return interrupt_signal() == 0;
}

void ConsoleProgress::end() {
  update(1.0);
  std::fprintf(stderr, " - done.\n");
}

void JsonProgress::begin(std::string_view step) {
  step_ = step;
  printed_ = -1;
  update(0.0);
}

bool JsonProgress::update(double fraction) {
  const int percent = int(std::clamp(fraction, 0.0, 1.0) * 100.0 + 1e-9);
  if (percent != printed_) {
    printed_ = percent;
    std::fprintf(stderr, "{\"step\":\"%s\",\"progress\":%.2f}\n", step_.c_str(), percent / 100.0);
    std::fflush(stderr);
  }
  return interrupt_signal() == 0;
}

void JsonProgress::end() { update(1.0); }

bool SilentProgress::update(double) { return interrupt_signal() == 0; }

void ProgressStep::update(double fraction) {
  stop_if_interrupted();
  if (!progress_.update(fraction)) throw Error(ErrorKind::cancelled, "cancelled");
}

namespace {
void print(std::string_view prefix, std::string_view tag, std::string_view message) {
  std::fprintf(stderr, "%.*s%s%.*s%.*s\n", int(prefix.size()), prefix.data(), prefix.empty() ? "" : ": ", int(tag.size()),
               tag.data(), int(message.size()), message.data());
}
}  // namespace

void Log::info(std::string_view message) const {
  if (level_ != LogLevel::quiet) print(prefix_, "", message);
}
void Log::detail(std::string_view message) const {
  if (level_ == LogLevel::verbose) print(prefix_, "", message);
}
void Log::warn(std::string_view message) const { print(prefix_, "warning: ", message); }

}  // namespace terrapolis
