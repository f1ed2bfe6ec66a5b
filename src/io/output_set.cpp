// SPDX-License-Identifier: MIT
#include "io/output_set.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/progress.hpp"
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

/// Removes the "<name>.tmp-<pid>" staging folders beside `path` (holding our marker, of this user)
/// of commands that died: the caller holds the output's lock, so no live command is writing them.
void remove_stale_staging(const fs::path& path) {
  const std::string prefix = path.filename().string() + ".tmp-";
  std::error_code ec;
  std::vector<fs::path> stale;
  for (const auto& entry : fs::directory_iterator(path.parent_path(), ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.empty() || !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); })) continue;
    struct stat marker {};
    if (::stat((entry.path() / kStagingMarker).c_str(), &marker) != 0 || marker.st_uid != ::getuid()) continue;
    if (std::atol(digits.c_str()) != long(::getpid())) stale.push_back(entry.path());
  }
  std::sort(stale.begin(), stale.end());
  for (const auto& dir : stale) {
    fs::remove_all(dir, ec);
    Log().warn("removed " + dir.string() + ", the temporary folder of a terrapolis command that was killed before it finished");
  }
}

/// The lock file that reserves the output `abs`, beside it.
fs::path lock_path(const fs::path& abs) { return abs.parent_path() / ("." + abs.filename().string() + ".terrapolis-lock"); }

Error appeared_meanwhile(const std::string& name) {
  return bad_input(name + ": appeared while this command ran (not written by terrapolis); nothing replaced, this command's output is discarded");
}

/// rename(2) that never replaces an existing `to` (renameat2's RENAME_NOREPLACE; where the file
/// system lacks it, a plain rename after a check: our lock keeps other terrapolis commands out).
void move_new(const fs::path& from, const fs::path& to, const std::string& name) {
  std::error_code ec;
  if (fs::is_directory(to, ec) && fs::is_empty(to, ec)) fs::remove(to, ec);  // an empty folder counts as new
  int rc = ::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE);
  if (rc != 0 && (errno == EINVAL || errno == ENOSYS)) {
    if (fs::exists(to, ec)) errno = EEXIST;
    else rc = ::rename(from.c_str(), to.c_str());
  }
  if (rc == 0) return;
  if (errno == EEXIST || errno == ENOTEMPTY)
    throw appeared_meanwhile(name);
  throw processing_error(to.string() + ": cannot move the new output in place (" + std::strerror(errno) + ")");
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
  std::error_code ec;
  if (!committed_)
    for (const auto& t : targets_) fs::remove_all(t.staging, ec);
  for (const auto& lock : locks_) {
    ::unlink(lock.path.c_str());  // before the unlock: a command waiting on this file retries on a new one
    ::close(lock.fd);
  }
}

void OutputSet::reserve(const fs::path& abs, const std::string& name) {
  const fs::path path = lock_path(abs);
  for (;;) {
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) throw processing_error(path.string() + ": cannot create the output's lock file (" + std::strerror(errno) + ")");
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      // The holder writes its pid just after it takes the lock: give it a few milliseconds.
      char pid[32] = {};
      ssize_t n = 0;
      for (int tries = 0; tries < 50 && (n = ::pread(fd, pid, sizeof pid - 1, 0)) <= 0; ++tries) ::usleep(2000);
      ::close(fd);
      const std::string holder = n > 0 ? " (pid " + std::string(pid, std::size_t(n)) + ")" : std::string();
      throw bad_input(name + ": another terrapolis command" + holder + " is writing this output; wait until it ends or choose another output");
    }
    struct stat held {}, now {};
    if (::fstat(fd, &held) == 0 && ::stat(path.c_str(), &now) == 0 && held.st_ino == now.st_ino && held.st_dev == now.st_dev) {
      // Our pid, for the message of a command refused meanwhile; a full disk leaves it empty (the lock holds all the same).
      const std::string pid = std::to_string(::getpid());
      if (::ftruncate(fd, 0) == 0 && ::pwrite(fd, pid.data(), pid.size(), 0) != ssize_t(pid.size())) (void)::ftruncate(fd, 0);
      locks_.push_back({path, fd});
      return;
    }
    ::close(fd);  // its holder removed it as we opened it: take the new one
  }
}

void OutputSet::check_target(const fs::path& path, bool is_folder) {
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
  reserve(abs, name);  // from here to the end no other terrapolis command writes this output
  remove_stale_staging(abs);
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
    if (old.written_by.empty())  // it was new or ours at declaration: something else made it meanwhile
      throw appeared_meanwhile(t.final_path.string());
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
    move_new(t.staging, t.final_path, t.final_path.string());
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
    if (fs::exists(t.final_path, ec)) move(written, t.final_path);  // one we wrote (checked at declaration)
    else move_new(written, t.final_path, t.final_path.string());
  }
  fs::remove_all(t.staging, ec);
}

std::string with_output_names(std::string message) {
  for (const auto& [staging, name] : staging_names())
    for (std::size_t at; (at = message.find(staging)) != std::string::npos;) message.replace(at, staging.size(), name);
  return message;
}

}  // namespace terrapolis
