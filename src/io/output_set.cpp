// SPDX-License-Identifier: MIT
#include "io/output_set.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <set>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "io/text_io.hpp"
#include "terrapolis/version.hpp"

namespace terrapolis {
namespace {

namespace fs = std::filesystem;

/// Marks a staging folder as ours, so that a later run may remove it once its process is gone.
constexpr const char* kStagingMarker = ".terrapolis-staging";

/// What a folder's manifest records: the files terrapolis wrote there and, for an output folder, the command.
struct Manifest {
  bool found = false;
  std::string written_by;  ///< command whose output folder this is; empty for files written into a user's folder
  std::set<std::string> files;
};

Manifest read_manifest(const fs::path& dir) {
  Manifest m;
  std::error_code ec;
  try {
    if (fs::exists(dir / kOutputsManifest, ec)) {
      const auto j = nlohmann::json::parse(read_text_file((dir / kOutputsManifest).string()));
      m.written_by = j.value("written_by", "");
      for (const auto& f : j.at("files")) m.files.insert(f.get<std::string>());
      m.found = true;
    } else if (fs::exists(dir / "run.json", ec)) {
      // A run folder written before the manifest existed: run.json lists its outputs, beside the QGIS styles.
      const auto j = nlohmann::json::parse(read_text_file((dir / "run.json").string()));
      for (const auto& o : j.at("outputs")) {
        const fs::path f = o.at("file").get<std::string>();
        m.files.insert(f.string());
        m.files.insert(f.stem().string() + ".qml");
      }
      m.files.insert("run.json");
      m.written_by = "run";
      m.found = true;
    }
  } catch (const nlohmann::json::exception&) {
    return Manifest{};  // unreadable: not a folder we can vouch for
  }
  return m;
}

void write_manifest(const fs::path& dir, const Manifest& m) {
  nlohmann::ordered_json j;
  j["terrapolis"] = version;
  if (!m.written_by.empty()) j["written_by"] = m.written_by;
  j["files"] = std::vector<std::string>(m.files.begin(), m.files.end());
  write_text_file((dir / kOutputsManifest).string(), j.dump(1) + "\n", true);
}

/// True when `inner` is `outer` or lies inside it (both absolute and normalised).
bool within(const fs::path& outer, const fs::path& inner) {
  auto o = outer.begin(), i = inner.begin();
  for (; o != outer.end() && !o->empty(); ++o, ++i)
    if (i == inner.end() || *o != *i) return false;
  return true;
}

fs::path absolute_path(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path), ec);
  if (ec) p = fs::absolute(path).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();  // "out/" is "out"
  return p;
}

/// Staging folders of this process and the outputs they stand for (one command per process).
std::vector<std::pair<std::string, std::string>>& staging_names() {
  static std::vector<std::pair<std::string, std::string>> names;
  return names;
}

bool process_gone(long pid) { return ::kill(pid_t(pid), 0) != 0 && errno == ESRCH; }

/// Removes "<name>.tmp-<pid>" staging folders beside `path` left by dead processes of this user.
void remove_stale_staging(const fs::path& path) {
  const std::string prefix = path.filename().string() + ".tmp-";
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(path.parent_path(), ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.empty() || !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); })) continue;
    struct stat marker {};
    if (::stat((entry.path() / kStagingMarker).c_str(), &marker) != 0 || marker.st_uid != ::getuid()) continue;
    const long pid = std::atol(digits.c_str());
    if (pid != long(::getpid()) && process_gone(pid)) fs::remove_all(entry.path(), ec);
  }
}

std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

void move(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (ec) throw processing_error(to.string() + ": cannot move the new output in place (" + ec.message() + ")");
}

}  // namespace

OutputSet::OutputSet(std::string command, std::vector<std::string> inputs, bool overwrite)
    : command_(std::move(command)), overwrite_(overwrite) {
  for (const auto& in : inputs)
    if (!in.empty()) inputs_.push_back(absolute_path(in));
}

OutputSet::~OutputSet() {
  if (committed_) return;
  std::error_code ec;
  for (const auto& t : targets_) fs::remove_all(t.staging, ec);
}

void OutputSet::check_target(const fs::path& path, bool is_folder) const {
  const std::string name = path.string();
  if (name.empty()) throw bad_input("output: the path is empty");
  const fs::path abs = absolute_path(name);
  const fs::path given_parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(abs.parent_path(), ec)) throw bad_input(name + ": output folder " + given_parent.string() + " does not exist");
  if (::access(abs.parent_path().c_str(), W_OK) != 0) throw bad_input(name + ": output folder " + given_parent.string() + " is not writable");
  if (abs == abs.root_path()) throw bad_input(name + ": is the root folder; refusing to write outputs over it");
  if (within(abs, absolute_path(fs::current_path(ec).string())))
    throw bad_input(name + ": is the current folder or one of its parents; refusing to write outputs over it");
  if (const char* home = std::getenv("HOME"); home && *home && within(abs, absolute_path(home)))
    throw bad_input(name + ": is the home folder or one of its parents; refusing to write outputs over it");
  for (const auto& in : inputs_) {
    if (abs == in) throw bad_input(name + ": is an input of this command; refusing to write over it");
    if (within(abs, in)) throw bad_input(name + ": holds the input " + in.string() + "; refusing to write over it");
  }
  if (!fs::exists(abs, ec)) return;
  if (is_folder) {
    if (!fs::is_directory(abs, ec)) throw bad_input(name + ": exists and is not a folder");
    if (fs::is_empty(abs, ec)) return;
    if (!overwrite_) throw bad_input(name + ": output folder exists (use --overwrite to replace what terrapolis wrote in it)");
    if (read_manifest(abs).written_by.empty())
      throw bad_input(name + ": is not an output folder of terrapolis (it has no " + kOutputsManifest +
                      "); --overwrite replaces only those, choose another folder");
  } else {
    if (fs::is_directory(abs, ec)) throw bad_input(name + ": is a folder, not a file");
    if (!overwrite_) throw bad_input(name + ": output exists (use --overwrite to replace it)");
    if (!read_manifest(abs.parent_path()).files.count(abs.filename().string()))
      throw bad_input(name + ": was not written by terrapolis (not in " + (given_parent / kOutputsManifest).string() +
                      "); --overwrite replaces only files terrapolis wrote");
  }
}

fs::path OutputSet::make_staging(const fs::path& path) {
  const fs::path abs = absolute_path(path.string());
  remove_stale_staging(abs);
  const fs::path staging = abs.parent_path() / (abs.filename().string() + ".tmp-" + std::to_string(::getpid()));
  staging_names().emplace_back(staging.string(), path.string());  // before anything can fail in it
  std::error_code ec;
  fs::remove_all(staging, ec);
  fs::create_directory(staging, ec);
  try {
    if (!ec) write_text_file((staging / kStagingMarker).string(), command_ + "\n", true);
  } catch (...) {
    fs::remove_all(staging, ec);  // not a target yet: the destructor would not remove it
    throw;
  }
  if (ec) throw processing_error(path.string() + ": cannot create a temporary folder beside it (" + ec.message() + ")");
  targets_.push_back({abs, staging, false});
  return staging;
}

fs::path OutputSet::folder(const std::string& dir, bool keep_files) {
  check_target(dir, true);
  const fs::path staging = make_staging(dir);
  targets_.back().is_folder = true;
  if (keep_files) {
    const fs::path abs = targets_.back().final_path;
    std::error_code ec;
    for (const auto& f : read_manifest(abs).files)
      if (fs::exists(abs / f, ec)) {
        fs::copy(abs / f, staging / f, fs::copy_options::recursive, ec);
        if (ec) throw processing_error((abs / f).string() + ": cannot copy it for the rerun (" + ec.message() + ")");
      }
  }
  return staging;
}

std::string OutputSet::file(const std::string& path) {
  check_target(path, false);
  const fs::path staging = make_staging(path);
  // Errors name the file itself, not its staging folder.
  staging_names().back().first = (staging / targets_.back().final_path.filename()).string();
  return staging_names().back().first;
}

void OutputSet::commit() {
  stop_if_interrupted();
  std::error_code ec;
  // Refuse, before anything moves, a new file whose name a user's file already takes in an output folder.
  for (const auto& t : targets_) {
    if (!t.is_folder || !fs::exists(t.final_path, ec) || fs::is_empty(t.final_path, ec)) continue;
    const Manifest old = read_manifest(t.final_path);
    for (const auto& f : entries(t.staging))
      if (f != kStagingMarker && fs::exists(t.final_path / f, ec) && !old.files.count(f))
        throw bad_input((t.final_path / f).string() + ": exists and was not written by terrapolis; move it away and rerun");
  }
  for (const auto& t : targets_) t.is_folder ? commit_folder(t) : commit_file(t);
  committed_ = true;
}

void OutputSet::commit_folder(const Target& t) const {
  std::error_code ec;
  fs::remove(t.staging / kStagingMarker, ec);
  Manifest now{true, command_, {}};
  for (const auto& f : entries(t.staging)) now.files.insert(f);
  if (!fs::exists(t.final_path, ec) || fs::is_empty(t.final_path, ec)) {
    write_manifest(t.staging, now);
    move(t.staging, t.final_path);  // rename(2) replaces an empty folder
    return;
  }
  // Record old and new files first: an interrupted commit leaves every file of ours recorded.
  const Manifest old = read_manifest(t.final_path);
  Manifest both = now;
  both.files.insert(old.files.begin(), old.files.end());
  write_manifest(t.final_path, both);
  for (const auto& f : now.files) {
    if (fs::is_directory(t.final_path / f, ec)) fs::remove_all(t.final_path / f, ec);
    move(t.staging / f, t.final_path / f);
  }
  for (const auto& f : old.files)
    if (!now.files.count(f)) fs::remove_all(t.final_path / f, ec);
  write_manifest(t.final_path, now);
  fs::remove_all(t.staging, ec);
}

void OutputSet::commit_file(const Target& t) const {
  std::error_code ec;
  const fs::path written = t.staging / t.final_path.filename();
  if (fs::exists(written, ec)) {
    Manifest m = read_manifest(t.final_path.parent_path());
    m.files.insert(t.final_path.filename().string());
    write_manifest(t.final_path.parent_path(), m);
    move(written, t.final_path);
  }
  fs::remove_all(t.staging, ec);
}

std::string with_output_names(std::string message) {
  for (const auto& [staging, name] : staging_names())
    for (std::size_t at; (at = message.find(staging)) != std::string::npos;) message.replace(at, staging.size(), name);
  return message;
}

}  // namespace terrapolis
