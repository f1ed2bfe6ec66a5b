// `terrapolis-mpi`: the command line on MPI ranks. Rank 0 parses and runs the command as
// `terrapolis` does; a tiled hydro request is handed to every rank, which processes the tiles dealt
// to it (TileDriver: round-robin, perimeters and global graphs gathered with MPI collectives).
// The only source that includes MPI.
// SPDX-License-Identifier: MIT
#include <mpi.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cli/command.hpp"
#include "cli/hydro_tiles.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "io/raster_io.hpp"

namespace terrapolis::cli {
namespace {

/// Tiles dealt round-robin to the ranks of MPI_COMM_WORLD.
class MpiTiles final : public hydro::tiled::TileDriver {
 public:
  MpiTiles() {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    // The test suite lowers it to exchange in many rounds on small grids.
    if (const char* bytes = std::getenv("TERRAPOLIS_MPI_EXCHANGE_BYTES")) round_bytes_ = std::clamp(std::atoll(bytes), 1LL, round_bytes_);
  }
  int rank() const override { return rank_; }
  int ranks() const override { return size_; }
  /// A new request: no failure agreed yet.
  void begin() { failed_ = false; }

  void share(std::vector<std::vector<char>>& per_tile, std::exception_ptr failure) override {
    if (failed_) {  // the error every rank agreed on, thrown again while it unwinds
      if (failure) std::rethrow_exception(failure);
      throw processing_error("tiles: another process failed");
    }
    agree_on_failures(failure);
    if (per_tile.empty()) return;
    const int tiles = int(per_tile.size());
    std::vector<long long> sizes(per_tile.size(), 0);
    for (int t = 0; t < tiles; ++t)
      if (owns(t)) sizes[std::size_t(t)] = (long long)per_tile[std::size_t(t)].size();
    MPI_Allreduce(MPI_IN_PLACE, sizes.data(), tiles, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    std::vector<long long> per_rank(std::size_t(size_), 0);
    for (int t = 0; t < tiles; ++t) per_rank[std::size_t(t % size_)] += sizes[std::size_t(t)];
    std::vector<std::size_t> start(static_cast<std::size_t>(size_));  // each rank's bytes in `all`
    long long total = 0;
    for (int r = 0; r < size_; ++r) start[std::size_t(r)] = std::size_t(total), total += per_rank[std::size_t(r)];
    std::vector<char> mine;
    mine.reserve(std::size_t(per_rank[std::size_t(rank_)]));
    for (int t = rank_; t < tiles; t += size_) mine.insert(mine.end(), per_tile[std::size_t(t)].begin(), per_tile[std::size_t(t)].end());
    std::vector<char> all(static_cast<std::size_t>(total));
    gather_in_rounds(mine, per_rank, start, all);
    mine = {};
    std::vector<std::size_t> at = start;
    for (int t = 0; t < tiles; ++t) {
      const std::size_t r = std::size_t(t % size_), n = std::size_t(sizes[std::size_t(t)]);
      if (!owns(t)) per_tile[std::size_t(t)].assign(all.begin() + std::ptrdiff_t(at[r]), all.begin() + std::ptrdiff_t(at[r] + n));
      at[r] += n;
    }
  }

 private:
  /// MPI_Allgatherv of every rank's `mine` (`per_rank` bytes, placed at `start` in `all`), in
  /// rounds: one call carries at most INT_MAX bytes in all (2 GB, counts being ints), and a round
  /// at most round_bytes_, each rank sending the next share of its bytes (round_bytes_ / ranks).
  void gather_in_rounds(const std::vector<char>& mine, const std::vector<long long>& per_rank, const std::vector<std::size_t>& start,
                        std::vector<char>& all) const {
    const long long share = std::max(1LL, round_bytes_ / size_);
    const long long largest = *std::max_element(per_rank.begin(), per_rank.end());
    std::vector<int> counts(static_cast<std::size_t>(size_)), displacements(counts.size());
    std::vector<char> part;
    for (long long from = 0; from == 0 || from < largest; from += share) {  // the same rounds on every rank
      int at = 0;
      for (int r = 0; r < size_; ++r) {
        counts[std::size_t(r)] = int(std::clamp(per_rank[std::size_t(r)] - from, 0LL, share));
        displacements[std::size_t(r)] = at;
        at += counts[std::size_t(r)];
      }
      part.resize(std::size_t(at));
      const char* sent = mine.data() + std::min<std::size_t>(std::size_t(from), mine.size());
      MPI_Allgatherv(sent, counts[std::size_t(rank_)], MPI_CHAR, part.data(), counts.data(), displacements.data(), MPI_CHAR, MPI_COMM_WORLD);
      for (int r = 0; r < size_; ++r)
        std::copy_n(part.begin() + displacements[std::size_t(r)], counts[std::size_t(r)], all.begin() + std::ptrdiff_t(start[std::size_t(r)] + std::size_t(from)));
    }
  }

  /// If a rank failed, every rank throws the lowest failing rank's error (its kind and message):
  /// rank 0 prints it once, and no rank waits for a message that will never come.
  void agree_on_failures(std::exception_ptr failure) {
    int first = failure ? rank_ : size_;
    MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (first == size_) return;
    failed_ = true;
    int kind = int(ErrorKind::processing);
    std::string message;
    if (rank_ == first) {
      try {
        std::rethrow_exception(failure);
      } catch (const Error& e) {
        kind = int(e.kind());
        message = e.what();
      } catch (const std::bad_alloc&) {
        message = "out of memory";
      } catch (const std::exception& e) {
        message = e.what();
      }
    }
    int length = int(message.size());
    MPI_Bcast(&kind, 1, MPI_INT, first, MPI_COMM_WORLD);
    MPI_Bcast(&length, 1, MPI_INT, first, MPI_COMM_WORLD);
    message.resize(std::size_t(length));
    MPI_Bcast(message.data(), length, MPI_CHAR, first, MPI_COMM_WORLD);
    if (rank_ == first) std::rethrow_exception(failure);
    throw Error(ErrorKind(kind), message + (first == 0 ? "" : " (MPI rank " + std::to_string(first) + ")"));
  }

  int rank_ = 0, size_ = 1;
  long long round_bytes_ = 256LL << 20;  ///< the most one exchange round carries in all (256 MiB)
  bool failed_ = false;
};

/// The fields of a tiled request and the worker threads, written or read in one order (`io` is
/// Encode or Decode): one list for both directions.
template <class IO>
void fields(IO& io, TiledHydroRequest& q, int& threads) {
  io(q.dem_path), io(q.out_dir), io(q.out_name);
  io(q.read.band), io(q.read.assume_crs), io(q.read.windowed);
  io(q.tile_size), io(q.memory_limit_mb), io(q.sea_level), io(q.unit), io(q.accumulation_scale), io(q.codes);
  io(q.filled), io(q.flowdir), io(q.accumulation), io(q.streams), io(q.streams_threshold_km2), io(q.basins);
  for (WriteOptions* w : {&q.filled_file, &q.flowdir_file, &q.accumulation_file, &q.basins_file}) {
    io(w->cog), io(w->overwrite), io(w->description), io(w->deflate_level);
    std::uint64_t n = w->metadata.size();
    io(n);
    w->metadata.resize(n);
    for (auto& [key, value] : w->metadata) io(key), io(value);
  }
  io(threads);
}

struct Encode {
  std::vector<char> bytes;
  template <class T>
  void operator()(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const char* p = reinterpret_cast<const char*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof v);
  }
  void operator()(const std::string& s) {
    (*this)(std::uint64_t(s.size()));
    bytes.insert(bytes.end(), s.begin(), s.end());
  }
  template <class T>
  void operator()(const std::optional<T>& v) {
    (*this)(v.has_value());
    if (v) (*this)(*v);
  }
};

struct Decode {
  const std::vector<char>& bytes;
  std::size_t at = 0;
  template <class T>
  void operator()(T& v) {
    std::memcpy(&v, bytes.data() + at, sizeof v);
    at += sizeof v;
  }
  void operator()(std::string& s) {
    std::uint64_t n = 0;
    (*this)(n);
    s.assign(bytes.data() + at, n);
    at += n;
  }
  template <class T>
  void operator()(std::optional<T>& v) {
    bool has = false;
    (*this)(has);
    if (!has) return v.reset();
    T value{};
    (*this)(value);
    v = std::move(value);
  }
};

/// What rank 0 broadcasts to the others: a request (its bytes follow) or the end, with the exit code.
enum Order : int { kEnd = 0, kRequest = 1 };

void broadcast_order(int order, int value) {
  int message[2] = {order, value};
  MPI_Bcast(message, 2, MPI_INT, 0, MPI_COMM_WORLD);
}

class MpiDistribution final : public TileDistribution {
 public:
  explicit MpiDistribution(MpiTiles& tiles) : tiles_(tiles) {}
  void start(const TiledHydroRequest& request, const Context& context) override {
    TiledHydroRequest q = request;
    int threads = context.threads;
    Encode out;
    fields(out, q, threads);
    broadcast_order(kRequest, int(out.bytes.size()));
    MPI_Bcast(out.bytes.data(), int(out.bytes.size()), MPI_CHAR, 0, MPI_COMM_WORLD);
    tiles_.begin();
  }
  hydro::tiled::TileDriver& driver() override { return tiles_; }

 private:
  MpiTiles& tiles_;
};

/// Ranks other than 0: each request's tiles, until rank 0 says the end; returns its exit code.
int serve(MpiTiles& tiles) {
  init_gdal();
  catch_interrupts();
  for (;;) {
    int order[2];
    MPI_Bcast(order, 2, MPI_INT, 0, MPI_COMM_WORLD);
    if (order[0] == kEnd) return order[1];
    std::vector<char> bytes(static_cast<std::size_t>(order[1]));
    MPI_Bcast(bytes.data(), order[1], MPI_CHAR, 0, MPI_COMM_WORLD);
    TiledHydroRequest q;
    int threads = 0;
    Decode in{bytes};
    fields(in, q, threads);
    std::optional<tbb::global_control> limit;
    if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    SilentProgress silent;
    Context context{Log(LogLevel::quiet), silent, threads};
    tiles.begin();
    try {
      run_tiled_hydro_tiles(q, context, tiles);
    } catch (...) {  // every rank has the same error; rank 0 reports it
    }
  }
}

}  // namespace
}  // namespace terrapolis::cli

int main(int argc, char** argv) {
  using namespace terrapolis::cli;
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);  // MPI from the main thread only
  // The cores of a node shared by its ranks (--threads may lower it).
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  int on_node = 1;
  MPI_Comm_size(node, &on_node);
  MPI_Comm_free(&node);
  const int cores = int(std::max(1u, std::thread::hardware_concurrency()));
  tbb::global_control share_of_node(tbb::global_control::max_allowed_parallelism, std::size_t(std::max(1, cores / on_node)));
  MpiTiles tiles;
  int code = 0;
  if (tiles.rank() == 0) {
    MpiDistribution distribution(tiles);
    set_tile_distribution(&distribution);
    code = run_command_line(argc, argv);
    set_tile_distribution(nullptr);
    broadcast_order(kEnd, code);
  } else {
    code = serve(tiles);
  }
  MPI_Finalize();
  return code;
}
