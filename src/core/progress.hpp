// Progress reporting with cancellation, and a levelled log; kept apart on purpose.
// SPDX-License-Identifier: MIT
#pragma once
#include <chrono>
#include <string>
#include <string_view>

namespace terrapolis {

/// Receives the progress of long work. Implementations: console (GDAL style), JSON lines (GUIs), silent.
class Progress {
 public:
  virtual ~Progress() = default;
  /// A new step starts (e.g. "fill"); fraction restarts at 0.
  virtual void begin(std::string_view step) = 0;
  /// Fraction of the current step done, in [0,1]. Returns false to ask the work to stop (every
  /// sink does after SIGINT/SIGTERM, see core/interrupt.hpp).
  virtual bool update(double fraction) = 0;
  /// The current step is finished.
  virtual void end() = 0;
  /// The step's estimated remaining time (seconds, from its pace so far) and what it is doing
  /// ("road 12 of 300"), before an update; sinks may show them with the next fraction.
  virtual void estimate(double /*remaining_s*/, std::string_view /*detail*/) {}
};

class SilentProgress final : public Progress {
 public:
  void begin(std::string_view) override {}
  bool update(double) override;
  void end() override {}
};

/// "step: 0...10...20...30...40...50...60...70...80...90...100 - done." on stderr, as GDAL prints.
class ConsoleProgress final : public Progress {
 public:
  void begin(std::string_view step) override;
  bool update(double fraction) override;
  void end() override;

  void estimate(double remaining_s, std::string_view detail) override;

 private:
  int printed_ = -1;  // last tick printed, in 2.5 % steps
  double remaining_s_ = -1;
};

/// One JSON object per line on stderr: {"step":"fill","progress":0.42}, for GUIs such as the QGIS provider.
class JsonProgress final : public Progress {
 public:
  void begin(std::string_view step) override;
  bool update(double fraction) override;
  void end() override;
  void estimate(double remaining_s, std::string_view detail) override;

 private:
  std::string step_, detail_;
  int printed_ = -1;  // last percent printed
  double remaining_s_ = -1;
};

/// Runs one named step on a Progress: begin on construction, end on destruction; `update`
/// throws Error(cancelled) when the sink asks to stop, and estimates the remaining time from the
/// pace so far (once 2 % is done), with an optional `detail` ("road 12 of 300").
class ProgressStep {
 public:
  ProgressStep(Progress& progress, std::string_view step) : progress_(progress), started_(std::chrono::steady_clock::now()) {
    progress_.begin(step);
  }
  ~ProgressStep() { progress_.end(); }
  ProgressStep(const ProgressStep&) = delete;
  ProgressStep& operator=(const ProgressStep&) = delete;
  void update(double fraction, std::string_view detail = {});

 private:
  Progress& progress_;
  std::chrono::steady_clock::time_point started_;
};

enum class LogLevel { quiet, normal, verbose };

/// Levelled messages on stderr, prefixed by the stage that writes them.
class Log {
 public:
  explicit Log(LogLevel level = LogLevel::normal, std::string prefix = {}) : level_(level), prefix_(std::move(prefix)) {}
  Log stage(std::string_view name) const { return Log(level_, std::string(name)); }
  void info(std::string_view message) const;
  void detail(std::string_view message) const;
  void warn(std::string_view message) const;
  LogLevel level() const { return level_; }

 private:
  LogLevel level_;
  std::string prefix_;
};

}  // namespace terrapolis
