// Flats that cross tile edges (Barnes et al. 2014b), drained by tiles: each tile's pieces of them,
// the two breadth-first distances solved in rounds of tiles that exchange their outer rings (as the
// spill graph is), and the directions each tile then gives its own cells.
// SPDX-License-Identifier: MIT
#include <algorithm>
#include <fstream>
#include <numeric>

#include "core/error.hpp"
#include "hydro/flow_directions.hpp"
#include "hydro/tiled/tiled_run.hpp"

namespace terrapolis::hydro::tiled {

// Why tiles give the whole grid's bytes. In drain_flats (flats.cpp) an undrained cell x of a flat L
// ends with the mask
//     m(x) = H + 1 - a(x) + 2 w(x)   when the wave from higher terrain reached x,
//     m(x) = 2 + 2 w(x)              otherwise,
// and the low edges (draining cells of L) with m = 2, where a(x) (w(x)) is the length in steps of
// the shortest 8-connected path from a high edge (a low edge) of L to x whose cells after the
// first are undrained cells of L, and H is the largest a + 1 over L's reached cells (0: none).
// Proof: wave() marks a cell when a cell of the previous ring reaches it and never again, so ring k
// holds exactly the cells at distance k - 1 from the seeds, whichever order a ring is visited in;
// the first wave stores ring = a + 1 (and flat_height its last, i.e. largest, ring), the second
// combines -(a + 1) with ring = w + 1 into H - (a + 1) + 2 (w + 1), or 2 (w + 1). The directions
// read masks only. So a and w are multi-source shortest-path lengths (a minimum over seeds and
// paths: no order of processing left), and they decompose over tiles: a shortest path that ends in
// tile T enters T for the last time from a cell h of T's halo (another tile's outer ring), so
//     a(x) = min(paths inside T from T's own seeds, min over h of a(h) + steps inside T from h),
// and the same for w. Each round, every tile whose halo changed solves that with its halo's current
// values; these are lengths of real paths, so they only decrease towards a(h), and a path that
// crosses tile edges j times is exact after j + 1 rounds: the rounds end, at the whole grid's values.
// A tile's interior depends on its halo only through its own ring, so an unchanged ring means an
// unchanged tile. Whether L has a low edge (drain_flats' label; none: every cell terminal) is
// whether it holds both undrained and draining cells, and H the largest over its pieces.

namespace {

bool out_code(std::uint8_t v) { return v == kNoData || v == kTerminal; }  // drain_flats' "outside" cells

/// The shared flats of one tile on `near`, the tile with a halo of one cell (first-pass codes
/// `first`): their cells in the tile numbered by piece, and the two distances over their
/// undrained cells. Halo cells only start paths, at the values their own tile gave them.
class TileFlats {
 public:
  TileFlats(const Dem& near, const Raster<std::uint8_t>& first)
      : near_(near), first_(first), piece_(near.size(), kNoPiece), away_(near.size(), kFar), towards_(near.size(), kFar) {
    for (int k = 0; k < 8; ++k) off_[k] = neighbour_offset(near.cols(), k);
    number_pieces(flats_reaching_halo(near, first));
  }

  std::vector<FlatPiece> pieces;

  bool any_undrained() const {
    return std::any_of(pieces.begin(), pieces.end(), [](const FlatPiece& p) { return p.undrained != 0; });
  }
  std::uint64_t undrained_cells() const {
    std::uint64_t n = 0;
    for (std::size_t i = 0; i < near_.size(); ++i) n += undrained(i);
    return n;
  }

  /// The two distances, `halo(c, row)` giving the RingCell of a halo cell of `near` (or nullptr).
  template <class Halo>
  void solve(Halo&& halo) {
    std::vector<std::pair<std::int32_t, std::uint32_t>> from_higher, from_lower;
    for (int row = 0; row < near_.rows(); ++row)
      for (int c = 0; c < near_.cols(); ++c) {
        const std::size_t i = near_.index(c, row);
        if (out_code(first_[i])) continue;
        if (!in_tile(c, row)) {
          const RingCell* h = halo(c, row);
          if (first_[i] == kNoFlow && h != nullptr && h->piece != kNoPiece) {
            if (h->away < kFar) from_higher.emplace_back(h->away, std::uint32_t(i));
            if (h->towards < kFar) from_lower.emplace_back(h->towards, std::uint32_t(i));
          }
        }
        if (first_[i] != kNoFlow && next_to_undrained(i)) from_lower.emplace_back(0, std::uint32_t(i));  // a low edge
        if (undrained(i) && next_to_higher(i)) from_higher.emplace_back(0, std::uint32_t(i));        // a high edge
      }
    away_ = distances(std::move(from_higher));
    towards_ = distances(std::move(from_lower));
    for (FlatPiece& p : pieces) p.height = 0;
    for (std::size_t i = 0; i < near_.size(); ++i)
      if (undrained(i) && away_[i] < kFar) pieces[piece_[i]].height = std::max(pieces[piece_[i]].height, away_[i] + 1);
  }

  /// The tile's outer ring (Ring order) as its neighbours will read it.
  std::vector<RingCell> ring(const TileRect& r) const {
    const Ring ring(r);
    std::vector<RingCell> out(ring.size(), RingCell{kNoPiece, kFar, kFar});
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c) {
        if (!ring.contains(c, row)) continue;
        const std::size_t i = near_.index(c + 1, row + 1);
        if (piece_[i] == kNoPiece) continue;
        out[ring.index(c, row)] = first_[i] == kNoFlow ? RingCell{piece_[i], away_[i], towards_[i]} : RingCell{piece_[i], kFar, 0};
      }
    return out;
  }

  /// Barnes 2014b's D8 over flats on the tile's undrained cells of shared flats: towards the
  /// neighbour of the same flat with the smallest mask, the first in neighbour order on ties;
  /// terminal when none is smaller, or when the flat has no low edge (`height(piece)` < 0).
  template <class Height>
  void direct(Raster<std::uint8_t>& d8, Height&& height) const {
    for (int row = 0; row < d8.rows(); ++row)
      for (int c = 0; c < d8.cols(); ++c) {
        const std::size_t i = near_.index(c + 1, row + 1);
        if (!undrained(i)) continue;
        const std::int32_t h = height(piece_[i]);
        int best = -1;
        std::int32_t best_mask = mask(i, h);
        for (int k = 0; k < 8 && h >= 0; ++k) {
          const std::size_t n = std::size_t(std::ptrdiff_t(i) + off_[k]);
          if (out_code(first_[n]) || near_[n] != near_[i]) continue;
          if (const std::int32_t m = mask(n, h); m < best_mask) {
            best_mask = m;
            best = k;
          }
        }
        d8(c, row) = best >= 0 ? std::uint8_t(best) : kTerminal;
      }
  }

 private:
  bool in_tile(int c, int row) const { return c > 0 && row > 0 && c + 1 < near_.cols() && row + 1 < near_.rows(); }
  bool undrained(std::size_t i) const { return piece_[i] != kNoPiece && first_[i] == kNoFlow; }
  bool next_to_undrained(std::size_t i) const {
    const int c = int(i % std::size_t(near_.cols())), row = int(i / std::size_t(near_.cols()));
    for (int k = 0; k < 8; ++k) {
      const int nc = c + dcol[k], nr = row + drow[k];
      if (near_.inside(nc, nr) && undrained(near_.index(nc, nr)) && near_(nc, nr) == near_[i]) return true;
    }
    return false;
  }
  bool next_to_higher(std::size_t i) const {  // a tile cell: its neighbours all lie in `near`
    for (int k = 0; k < 8; ++k) {
      const std::size_t n = std::size_t(std::ptrdiff_t(i) + off_[k]);
      if (!out_code(first_[n]) && near_[n] > near_[i]) return true;
    }
    return false;
  }
  std::int32_t mask(std::size_t i, std::int32_t height) const {
    if (first_[i] != kNoFlow) return 2;  // a low edge
    return away_[i] < kFar ? height + 1 - away_[i] + 2 * towards_[i] : 2 + 2 * towards_[i];
  }

  /// The cells of shared flats in the tile, by piece (8-connected, one elevation, inside the tile).
  void number_pieces(const std::vector<std::uint8_t>& member) {
    std::vector<std::size_t> stack;
    for (int row = 1; row + 1 < near_.rows(); ++row)
      for (int c = 1; c + 1 < near_.cols(); ++c) {
        const std::size_t s = near_.index(c, row);
        if (!member[s] || piece_[s] != kNoPiece) continue;
        const std::uint32_t id = std::uint32_t(pieces.size());
        FlatPiece p{0, 0, 0};
        piece_[s] = id;
        stack.push_back(s);
        while (!stack.empty()) {
          const std::size_t i = stack.back();
          stack.pop_back();
          (first_[i] == kNoFlow ? p.undrained : p.draining) = 1;
          const int ic = int(i % std::size_t(near_.cols())), ir = int(i / std::size_t(near_.cols()));
          for (int k = 0; k < 8; ++k) {
            const std::size_t n = std::size_t(std::ptrdiff_t(i) + off_[k]);
            if (!in_tile(ic + dcol[k], ir + drow[k]) || piece_[n] != kNoPiece || !member[n] || near_[n] != near_[i]) continue;
            piece_[n] = id;
            stack.push_back(n);
          }
        }
        pieces.push_back(p);
      }
  }

  /// Breadth-first distances from `seeds` (distance, index in `near`), over the tile's undrained
  /// cells of shared flats, one step between 8-neighbours of one elevation; a seed keeps its value.
  std::vector<std::int32_t> distances(std::vector<std::pair<std::int32_t, std::uint32_t>> seeds) const {
    std::vector<std::int32_t> d(near_.size(), kFar);
    std::sort(seeds.begin(), seeds.end());
    std::vector<std::uint32_t> front, next;
    std::size_t s = 0;
    for (std::int32_t level = 0;; ++level) {
      if (front.empty()) {
        if (s == seeds.size()) break;
        level = std::max(level, seeds[s].first);
      }
      for (; s < seeds.size() && seeds[s].first <= level; ++s)
        if (d[seeds[s].second] > seeds[s].first) {
          d[seeds[s].second] = seeds[s].first;
          front.push_back(seeds[s].second);
        }
      next.clear();
      for (const std::uint32_t i : front)
        for (int k = 0; k < 8; ++k) {
          const std::size_t n = std::size_t(std::ptrdiff_t(i) + off_[k]);
          if (n >= near_.size() || !undrained(n) || d[n] <= level + 1 || near_[n] != near_[i]) continue;
          d[n] = level + 1;
          next.push_back(std::uint32_t(n));
        }
      std::swap(front, next);
    }
    return d;
  }

  const Dem& near_;
  const Raster<std::uint8_t>& first_;
  std::ptrdiff_t off_[8];
  std::vector<std::uint32_t> piece_;
  std::vector<std::int32_t> away_, towards_;
};

/// Union-find over the pieces of shared flats.
struct Sets {
  std::vector<std::uint32_t> parent;
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

void write_window(const std::string& path, const Dem& near, const Raster<std::uint8_t>& first) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(near.data()), std::streamsize(near.size() * sizeof(float)));
  out.write(reinterpret_cast<const char*>(first.data()), std::streamsize(first.size()));
  if (!out) throw bad_input(path + ": cannot write scratch data (disk full?)");
}

void read_window(const std::string& path, Dem& near, Raster<std::uint8_t>& first) {
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(near.data()), std::streamsize(near.size() * sizeof(float)));
  in.read(reinterpret_cast<char*>(first.data()), std::streamsize(first.size()));
  if (!in) throw bad_input(path + ": cannot read scratch data back");
}

}  // namespace

// Pass 2, for a tile with cells of flats that reach its halo: the pieces, the outer ring before any
// wave, and the window (5 bytes a cell) kept on a scratch file for the rounds.
void TiledRun::share_tile_flats(int t, const TileRect& r, const Dem& near, const Raster<std::uint8_t>& first) {
  TileFlats f(near, first);
  ring_[std::size_t(t)] = f.ring(r);
  if (f.any_undrained()) {
    flat_tile_[std::size_t(t)] = 1;
    flat_cells_[std::size_t(t)] = f.undrained_cells();
    write_window(flats_path(t), near, first);
  }
  pieces_[std::size_t(t)] = std::move(f.pieces);
}

const RingCell* TiledRun::ring_cell(int gc, int gr) const {
  if (off_mosaic(gc, gr)) return nullptr;
  const int u = grid_.tile_of(gc, gr);
  if (ring_[std::size_t(u)].empty()) return nullptr;
  const TileRect ru = grid_.rect(u);
  return &ring_[std::size_t(u)][Ring(ru).index(gc - ru.col0, gr - ru.row0)];
}

// The pieces joined into flats across tile edges: 8-neighbours of one elevation in two tiles.
void TiledRun::join_pieces() {
  piece_base_.assign(std::size_t(tiles_) + 1, 0);
  for (int t = 0; t < tiles_; ++t) piece_base_[std::size_t(t) + 1] = piece_base_[std::size_t(t)] + std::uint32_t(pieces_[std::size_t(t)].size());
  Sets sets{std::vector<std::uint32_t>(piece_base_.back())};
  std::iota(sets.parent.begin(), sets.parent.end(), 0u);
  for (int t = 0; t < tiles_; ++t) {
    if (ring_[std::size_t(t)].empty()) continue;
    const TileRect r = grid_.rect(t);
    const Ring ring(r);
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c) {
        if (!ring.contains(c, row)) continue;
        const std::uint32_t p = ring_[std::size_t(t)][ring.index(c, row)].piece;
        if (p == kNoPiece) continue;
        const int gc = r.col0 + c, gr = r.row0 + row;
        float z, zn;
        std::uint32_t label, label_n;
        frame_cell(gc, gr, z, label);
        for (int k = 0; k < 8; ++k) {
          const int nc = gc + dcol[k], nr = gr + drow[k];
          const RingCell* n = ring_cell(nc, nr);
          if (n == nullptr || n->piece == kNoPiece || grid_.tile_of(nc, nr) == t) continue;
          frame_cell(nc, nr, zn, label_n);
          if (final_z(zn, label_n) == final_z(z, label))
            sets.join(piece_base_[std::size_t(t)] + p, piece_base_[std::size_t(grid_.tile_of(nc, nr))] + n->piece);
        }
      }
  }
  flat_of_.resize(sets.parent.size());
  for (std::uint32_t g = 0; g < flat_of_.size(); ++g) flat_of_[g] = sets.find(g);
}

// 3. The flats that cross tile edges, by rounds of tiles (see the proof above), then each flat's
// height and whether it drains.
void TiledRun::solve_shared_flats() {
  join_pieces();
  fresh_ring_.assign(static_cast<std::size_t>(tiles_), {});
  std::vector<std::uint8_t> solving = flat_tile_;
  double ring_bytes = 0;
  for (const auto& ring : ring_) ring_bytes += double(ring.size()) * sizeof(RingCell);
  do {
    ++report_.flat_rounds;
  } while (flat_round(solving));
  fresh_ring_ = {};
  const std::size_t n = flat_of_.size();
  std::vector<std::uint8_t> undrained(n, 0), draining(n, 0);
  flat_height_.assign(n, 0);
  for (int t = 0; t < tiles_; ++t)
    for (std::size_t j = 0; j < pieces_[std::size_t(t)].size(); ++j) {
      const FlatPiece& p = pieces_[std::size_t(t)][j];
      const std::uint32_t f = flat_of_[piece_base_[std::size_t(t)] + j];
      undrained[f] |= p.undrained;
      draining[f] |= p.draining;
      flat_height_[f] = std::max(flat_height_[f], p.height);
    }
  for (std::size_t f = 0; f < n; ++f)
    if (!undrained[f] || !draining[f]) flat_height_[f] = -1;
  report_.flat_cells_shared = std::accumulate(flat_cells_.begin(), flat_cells_.end(), std::uint64_t(0));
  // The rings twice (the round's and the fresh one) and per piece its record, base, flat and height.
  report_.global_state_bytes = std::max(report_.global_state_bytes, frame_bytes_ + 2 * ring_bytes + double(n) * (sizeof(FlatPiece) + 14));
}

/// One round: the tiles in `solving` solve their flats from their halos; on return, `solving` holds
/// the tiles next to a tile whose ring changed, and whether there are any.
bool TiledRun::flat_round(std::vector<std::uint8_t>& solving) {
  std::exception_ptr failure = for_tiles("flats across tiles", [&](int t, const TileRect& r) {
    if (solving[std::size_t(t)]) solve_tile_flats(t, r, fresh_ring_[std::size_t(t)]);
  });
  exchange(
      failure,
      [&](int t, std::vector<char>& out) {
        if (!solving[std::size_t(t)]) return;
        put(out, fresh_ring_[std::size_t(t)]);
        put(out, pieces_[std::size_t(t)]);
      },
      [&](int t, Unpack& in) {
        if (!solving[std::size_t(t)]) return;
        fresh_ring_[std::size_t(t)] = in.take<RingCell>();
        pieces_[std::size_t(t)] = in.take<FlatPiece>();
      });
  std::vector<std::uint8_t> changed(static_cast<std::size_t>(tiles_), 0);
  for (int t = 0; t < tiles_; ++t) {
    if (!solving[std::size_t(t)]) continue;
    changed[std::size_t(t)] = fresh_ring_[std::size_t(t)] != ring_[std::size_t(t)];
    ring_[std::size_t(t)].swap(fresh_ring_[std::size_t(t)]);
    fresh_ring_[std::size_t(t)] = {};
  }
  bool any = false;
  for (int t = 0; t < tiles_; ++t) {
    const int i = t % grid_.across(), j = t / grid_.across();
    bool next_to_change = false;
    for (int k = 0; k < 8; ++k) {
      const int ni = i + dcol[k], nj = j + drow[k];
      if (ni >= 0 && nj >= 0 && ni < grid_.across() && nj < grid_.down()) next_to_change |= changed[std::size_t(nj * grid_.across() + ni)] != 0;
    }
    solving[std::size_t(t)] = flat_tile_[std::size_t(t)] && next_to_change;
    any |= solving[std::size_t(t)] != 0;
  }
  return any;
}

void TiledRun::solve_tile_flats(int t, const TileRect& r, std::vector<RingCell>& ring) {
  Dem near(r.cols + 2, r.rows + 2, shifted(georef_, r.col0 - 1, r.row0 - 1));
  Raster<std::uint8_t> first = near.like<std::uint8_t>(kNoData);
  read_window(flats_path(t), near, first);
  TileFlats f(near, first);
  f.solve([&](int c, int row) { return ring_cell(r.col0 - 1 + c, r.row0 - 1 + row); });
  ring = f.ring(r);
  pieces_[std::size_t(t)] = std::move(f.pieces);
}

// Pass 3's start: the tile's undrained cells of shared flats given their directions.
void TiledRun::direct_tile_flats(int t, const TileRect& r, Raster<std::uint8_t>& d8) const {
  Dem near(r.cols + 2, r.rows + 2, shifted(georef_, r.col0 - 1, r.row0 - 1));
  Raster<std::uint8_t> first = near.like<std::uint8_t>(kNoData);
  read_window(flats_path(t), near, first);
  TileFlats f(near, first);
  f.solve([&](int c, int row) { return ring_cell(r.col0 - 1 + c, r.row0 - 1 + row); });
  f.direct(d8, [&](std::uint32_t piece) { return flat_height_[flat_of_[piece_base_[std::size_t(t)] + piece]]; });
}

}  // namespace terrapolis::hydro::tiled
