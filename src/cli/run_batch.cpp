// SPDX-License-Identifier: MIT
#include "cli/run_batch.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "pipeline/scenario.hpp"

extern char** environ;

namespace terrapolis::cli {
namespace {

namespace fs = std::filesystem;

struct Job {
  std::string scenario;  ///< as given
  std::string output;    ///< the run folder, absolute
  std::string refused;   ///< why it was not started ("" when it was)
  pid_t pid = 0;
  FILE* log = nullptr;   ///< the run's stderr
  std::chrono::steady_clock::time_point started;
  int code = -1;         ///< exit code; -1: not run
  double seconds = 0;
  std::string message;   ///< the run's error line
};

std::string absolute(const std::string& path) { return fs::absolute(path).lexically_normal().string(); }

/// The `terrapolis run` command line of one scenario of the batch.
std::vector<std::string> run_arguments(const BatchRequest& r, const Job& job, int threads) {
  std::vector<std::string> a = {"--quiet", "--progress", "none", "--threads", std::to_string(threads), "run", job.scenario,
                                "--output", job.output};
  for (const auto& s : r.sets) a.insert(a.end(), {"--set", s});
  if (r.seed) a.insert(a.end(), {"--seed", std::to_string(*r.seed)});
  if (r.overwrite) a.push_back("--overwrite");
  if (!r.from.empty()) a.insert(a.end(), {"--from", r.from});
  if (!r.until.empty()) a.insert(a.end(), {"--until", r.until});
  if (!r.only.empty()) {
    a.push_back("--only");
    a.insert(a.end(), r.only.begin(), r.only.end());
  }
  return a;
}

void start(Job& job, const std::vector<std::string>& arguments) {
  static const std::string self = fs::read_symlink("/proc/self/exe").string();
  std::vector<char*> argv = {const_cast<char*>(self.c_str())};
  for (const auto& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  job.log = std::tmpfile();
  if (!job.log) throw processing_error("batch: cannot create a temporary file for a run's messages");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, fileno(job.log), STDERR_FILENO);
  const int rc = posix_spawn(&job.pid, self.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw processing_error(job.scenario + ": cannot start its run (" + std::string(std::strerror(rc)) + ")");
  job.started = std::chrono::steady_clock::now();
}

/// Reads what the ended run printed: its error line becomes the job's message, other lines
/// (warnings) are passed on, prefixed by the scenario.
void finish(Job& job, int status, const Log& log) {
  job.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  job.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - job.started).count();
  std::rewind(job.log);
  char line[4096];
  while (std::fgets(line, sizeof line, job.log)) {
    std::string text(line);
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    if (text.empty()) continue;
    // The run's last word ("terrapolis: error: ...", "terrapolis: interrupted ...") is its outcome; other lines are passed on.
    static const std::string own = "terrapolis: ", error = "terrapolis: error: ";
    if (text.rfind(own, 0) == 0) {
      job.message = text.substr(text.rfind(error, 0) == 0 ? error.size() : own.size());
    } else {
      log.warn(job.scenario + ": " + text);
    }
  }
  std::fclose(job.log);
  job.log = nullptr;
  if (job.code > 128 && job.message.empty()) job.message = "ended by signal " + std::to_string(job.code - 128);
}

std::string outcome(const Job& j) {
  if (!j.refused.empty()) return "refused: " + j.refused;
  if (j.code < 0) return "not run (interrupted)";
  if (j.code == 0) return "ok";
  return "exit " + std::to_string(j.code) + (j.message.empty() ? "" : ": " + j.message);
}

void print_table(const std::vector<Job>& jobs) {
  std::size_t w_scenario = 8, w_output = 10;
  for (const auto& j : jobs) {
    w_scenario = std::max(w_scenario, j.scenario.size());
    w_output = std::max(w_output, fs::relative(j.output).string().size());
  }
  std::printf("%-*s  %-*s  %7s  %s\n", int(w_scenario), "scenario", int(w_output), "run folder", "time", "outcome");
  int ok = 0;
  for (const auto& j : jobs) {
    const std::string time = j.code >= 0 ? [&] { char b[32]; std::snprintf(b, sizeof b, "%.1f s", j.seconds); return std::string(b); }() : "-";
    std::printf("%-*s  %-*s  %7s  %s\n", int(w_scenario), j.scenario.c_str(), int(w_output), fs::relative(j.output).string().c_str(),
                time.c_str(), outcome(j).c_str());
    ok += j.code == 0;
  }
  std::printf("%d of %zu runs succeeded\n", ok, jobs.size());
}

}  // namespace

bool is_batch(const std::vector<std::string>& paths) {
  std::error_code ec;
  return paths.size() > 1 || (paths.size() == 1 && fs::is_directory(paths[0], ec));
}

std::vector<std::string> batch_scenarios(const std::vector<std::string>& paths) {
  std::error_code ec;
  if (paths.size() != 1 || !fs::is_directory(paths[0], ec)) return paths;
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(paths[0], ec))
    if (e.is_regular_file(ec) && e.path().extension() == ".json") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw bad_input(paths[0] + ": holds no scenario (no *.json file)");
  return files;
}

void run_batch(const BatchRequest& r, const Log& log) {
  if (r.jobs < 1) throw bad_input("--jobs: must be at least 1");
  std::vector<Job> jobs;
  std::map<std::string, std::string> taken;  // run folder -> the scenario that writes it
  for (const auto& file : batch_scenarios(r.scenarios)) {
    Job job;
    job.scenario = file;
    try {
      std::vector<std::string> sets = r.sets;
      if (r.parent) {
        job.output = absolute((fs::path(*r.parent) / fs::path(file).stem()).string());
        sets.push_back("output=" + nlohmann::json(job.output).dump());
      }
      const pipeline::Scenario scenario = pipeline::load_scenario(file, sets, r.seed);
      job.output = absolute(scenario.path("output"));
      if (const auto [at, fresh] = taken.emplace(job.output, file); !fresh)
        job.refused = "its run folder is " + at->second + "'s too";
    } catch (const Error& e) {
      job.refused = e.what();
      if (job.refused.rfind(file + ": ", 0) == 0) job.refused.erase(0, file.size() + 2);  // the table's row names it
    }
    jobs.push_back(std::move(job));
  }
  const int cores = r.threads > 0 ? r.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  const int threads = std::max(1, cores / r.jobs);
  std::size_t next = 0, running = 0, done = 0;
  const std::size_t runnable = std::size_t(std::count_if(jobs.begin(), jobs.end(), [](const Job& j) { return j.refused.empty(); }));
  bool forwarded = false;
  while (done < runnable) {
    for (; running < std::size_t(r.jobs) && next < jobs.size() && !interrupt_signal(); ++next)
      if (jobs[next].refused.empty()) {
        start(jobs[next], run_arguments(r, jobs[next], threads));
        ++running;
        log.info("batch: started " + jobs[next].scenario + " into " + fs::relative(jobs[next].output).string());
      }
    if (running == 0) break;  // interrupted before the rest started
    bool reaped = false;
    for (auto& j : jobs) {
      int status = 0;
      if (j.pid > 0 && j.code < 0 && ::waitpid(j.pid, &status, WNOHANG) == j.pid) {
        finish(j, status, log);
        --running, ++done, reaped = true;
        log.info("batch: " + j.scenario + ": " + outcome(j));
      }
    }
    if (interrupt_signal() && !forwarded) {
      for (const auto& j : jobs)
        if (j.pid > 0 && j.code < 0) ::kill(j.pid, interrupt_signal());
      forwarded = true;
    }
    if (!reaped) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (log.level() != LogLevel::quiet) print_table(jobs);
  stop_if_interrupted();
  const auto failed = std::count_if(jobs.begin(), jobs.end(), [](const Job& j) { return j.code != 0; });
  if (failed == 0) return;
  const bool all_refused = std::all_of(jobs.begin(), jobs.end(), [](const Job& j) { return j.code == 0 || j.code == 2 || !j.refused.empty(); });
  const std::string what = "batch: " + std::to_string(failed) + " of " + std::to_string(jobs.size()) + " runs did not succeed (the table above)";
  throw all_refused ? bad_input(what) : processing_error(what);
}

}  // namespace terrapolis::cli
