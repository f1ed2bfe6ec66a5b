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
    // Every 10 %, the time left when the step is long enough for it to matter.
    if (printed_ % 4 == 0 && printed_ < 40 && remaining_s_ >= 10) std::fprintf(stderr, " (%.0f s left) ", remaining_s_);
  }
  std::fflush(stderr);
  return interrupt_signal() == 0;
}

void ConsoleProgress::estimate(double remaining_s, std::string_view) { remaining_s_ = remaining_s; }

void ConsoleProgress::end() {
  update(1.0);
  std::fprintf(stderr, " - done.\n");
}

void JsonProgress::begin(std::string_view step) {
  step_ = step;
  detail_.clear();
  remaining_s_ = -1;
  printed_ = -1;
  update(0.0);
}

bool JsonProgress::update(double fraction) {
  const int percent = int(std::clamp(fraction, 0.0, 1.0) * 100.0 + 1e-9);
  if (percent != printed_) {
    printed_ = percent;
    std::string extra;
    if (remaining_s_ >= 0) extra += ",\"eta_s\":" + std::to_string(int(remaining_s_ + 0.5));
    if (!detail_.empty()) extra += ",\"detail\":\"" + detail_ + "\"";  // plain ASCII text of ours: no escaping needed
    std::fprintf(stderr, "{\"step\":\"%s\",\"progress\":%.2f%s}\n", step_.c_str(), percent / 100.0, extra.c_str());
    std::fflush(stderr);
  }
  return interrupt_signal() == 0;
}

void JsonProgress::estimate(double remaining_s, std::string_view detail) {
  remaining_s_ = remaining_s;
  detail_ = detail;
}

void JsonProgress::end() {
  remaining_s_ = 0;
  update(1.0);
}

bool SilentProgress::update(double) { return interrupt_signal() == 0; }

void ProgressStep::update(double fraction, std::string_view detail) {
  stop_if_interrupted();
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  progress_.estimate(fraction >= 0.02 ? elapsed * (1 - std::min(fraction, 1.0)) / fraction : -1, detail);
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
