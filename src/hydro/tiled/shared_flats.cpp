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

// A tile cell's word: kNoPiece, or its piece with these bits.
constexpr std::uint32_t kUndrained = 1u << 30, kHighEdge = 1u << 31, kPieceBits = kUndrained - 1;

/// A tile's cells of shared flats as pass 2 finds them, kept on the scratch folder for the rounds:
/// a word per cell (its piece, whether it is undrained and a high edge), the filled values of the
/// tile's outer ring, and the filled values and first-pass codes of its halo: all that the two
/// distances and the directions read (4 bytes a cell and 17 a ring cell).
struct FlatCells {
  std::vector<std::uint32_t> word;  // by tile cell, row-major
  std::vector<float> ring_z;        // Ring(tile) order
  std::vector<float> halo_z;        // Ring(window) order: the window's outer ring is the halo
  std::vector<std::uint8_t> halo_code;
  std::vector<FlatPiece> pieces;
};

TileRect window_of(const TileRect& r) { return {r.col0 - 1, r.row0 - 1, r.cols + 2, r.rows + 2}; }

/// Pass 2: the cells of `near` (the tile `r` with a halo of one cell, first-pass codes `first`)
/// in flats that reach the halo (`member`), numbered by piece (connected inside the tile).
FlatCells find_flat_cells(const TileRect& r, const Dem& near, const Raster<std::uint8_t>& first, const std::vector<std::uint8_t>& member) {
  FlatCells f;
  f.word.assign(std::size_t(r.cols) * std::size_t(r.rows), kNoPiece);
  std::vector<std::size_t> stack;
  auto word = [&](int c, int row) -> std::uint32_t& { return f.word[std::size_t(row - 1) * std::size_t(r.cols) + std::size_t(c - 1)]; };
  for (int row = 1; row <= r.rows; ++row)
    for (int c = 1; c <= r.cols; ++c) {
      if (!member[near.index(c, row)] || word(c, row) != kNoPiece) continue;
      const std::uint32_t id = std::uint32_t(f.pieces.size());
      if (id >= kPieceBits) throw processing_error("tiles: too many pieces of flats in a tile");
      FlatPiece p{0, 0, 0};
      word(c, row) = id;
      stack.push_back(near.index(c, row));
      while (!stack.empty()) {
        const std::size_t i = stack.back();
        stack.pop_back();
        const int ic = int(i % std::size_t(near.cols())), ir = int(i / std::size_t(near.cols()));
        (first[i] == kNoFlow ? p.undrained : p.draining) = 1;
        for (int k = 0; k < 8; ++k) {
          const int nc = ic + dcol[k], nr = ir + drow[k];
          if (nc < 1 || nr < 1 || nc > r.cols || nr > r.rows || word(nc, nr) != kNoPiece) continue;
          const std::size_t n = near.index(nc, nr);
          if (!member[n] || near[n] != near[i]) continue;
          word(nc, nr) = id;
          stack.push_back(n);
        }
      }
      f.pieces.push_back(p);
    }
  for (int row = 1; row <= r.rows; ++row)
    for (int c = 1; c <= r.cols; ++c) {
      std::uint32_t& w = word(c, row);
      const std::size_t i = near.index(c, row);
      if (w == kNoPiece || first[i] != kNoFlow) continue;
      w |= kUndrained;
      for (int k = 0; k < 8; ++k) {
        const std::size_t n = near.index(c + dcol[k], row + drow[k]);
        if (!out_code(first[n]) && near[n] > near[i]) w |= kHighEdge;  // Barnes 2014b's high edge
      }
    }
  const Ring ring(r), halo(window_of(r));
  f.ring_z.resize(ring.size());
  f.halo_z.resize(halo.size());
  f.halo_code.resize(halo.size());
  for (int row = 0; row < near.rows(); ++row)
    for (int c = 0; c < near.cols(); ++c) {
      if (halo.contains(c, row)) {
        f.halo_z[halo.index(c, row)] = near(c, row);
        f.halo_code[halo.index(c, row)] = first(c, row);
      } else if (ring.contains(c - 1, row - 1)) {
        f.ring_z[ring.index(c - 1, row - 1)] = near(c, row);
      }
    }
  return f;
}

/// The two distances and the directions of one tile's shared flats, on its FlatCells. Halo cells
/// only start paths, at the values their own tile gave them; `halo(c, row)` (tile coordinates,
/// one off the tile) gives that RingCell, or nullptr.
class TileFlats {
 public:
  TileFlats(const TileRect& r, const FlatCells& f)
      : cols_(r.cols), rows_(r.rows), ring_(r), halo_(window_of(r)), f_(f), away_(f.word.size(), kFar), towards_(f.word.size(), kFar) {}

  std::uint64_t undrained_cells() const {
    return std::uint64_t(std::count_if(f_.word.begin(), f_.word.end(), [](std::uint32_t w) { return undrained(w); }));
  }

  template <class Halo>
  void solve(Halo&& halo, std::vector<FlatPiece>& pieces) {
    std::vector<std::pair<std::int32_t, std::uint32_t>> from_higher, from_lower;
    for (int row = 0; row < rows_; ++row)
      for (int c = 0; c < cols_; ++c) {
        const std::uint32_t i = std::uint32_t(index(c, row)), w = f_.word[i];
        if (!undrained(w)) continue;
        if (w & kHighEdge) from_higher.emplace_back(0, i);
        bool low = false;  // next to a low edge, a draining cell of the flat
        for (int k = 0; k < 8; ++k) {
          const int nc = c + dcol[k], nr = row + drow[k];
          if (inside(nc, nr)) {
            const std::uint32_t wn = f_.word[index(nc, nr)];
            low |= wn != kNoPiece && !undrained(wn) && same_piece(w, wn);
          } else if (same_flat_in_halo(c, row, nc, nr)) {
            if (f_.halo_code[halo_.index(nc + 1, nr + 1)] != kNoFlow) {
              low = true;
            } else if (const RingCell* h = halo(nc, nr); h != nullptr && h->piece != kNoPiece) {
              if (h->away < kFar) from_higher.emplace_back(h->away + 1, i);
              if (h->towards < kFar) from_lower.emplace_back(h->towards + 1, i);
            }
          }
        }
        if (low) from_lower.emplace_back(1, i);
      }
    away_ = distances(std::move(from_higher));
    towards_ = distances(std::move(from_lower));
    for (FlatPiece& p : pieces) p.height = 0;
    for (std::size_t i = 0; i < f_.word.size(); ++i)
      if (undrained(f_.word[i]) && away_[i] < kFar) {
        std::int32_t& h = pieces[f_.word[i] & kPieceBits].height;
        h = std::max(h, away_[i] + 1);
      }
  }

  /// The tile's outer ring (Ring order) as its neighbours will read it.
  std::vector<RingCell> ring() const {
    std::vector<RingCell> out(ring_.size(), RingCell{kNoPiece, kFar, kFar});
    for (int row = 0; row < rows_; ++row)
      for (int c = 0; c < cols_; ++c) {
        if (!ring_.contains(c, row)) continue;
        const std::size_t i = index(c, row);
        const std::uint32_t w = f_.word[i];
        if (w == kNoPiece) continue;
        out[ring_.index(c, row)] = undrained(w) ? RingCell{w & kPieceBits, away_[i], towards_[i]} : RingCell{w & kPieceBits, kFar, 0};
      }
    return out;
  }

  /// Barnes 2014b's D8 over flats on the tile's undrained cells of shared flats: towards the
  /// neighbour of the same flat with the smallest mask, the first in neighbour order on ties;
  /// terminal when none is smaller, or when the flat has no low edge (`height(piece)` < 0).
  template <class Height, class Halo>
  void direct(Raster<std::uint8_t>& d8, Height&& height, Halo&& halo) const {
    for (int row = 0; row < rows_; ++row)
      for (int c = 0; c < cols_; ++c) {
        const std::size_t i = index(c, row);
        const std::uint32_t w = f_.word[i];
        if (!undrained(w)) continue;
        const std::int32_t h = height(w & kPieceBits);
        int best = -1;
        std::int32_t best_mask = mask(away_[i], towards_[i], h);
        for (int k = 0; k < 8 && h >= 0; ++k) {
          const int nc = c + dcol[k], nr = row + drow[k];
          std::int32_t m = best_mask;
          if (inside(nc, nr)) {
            const std::size_t n = index(nc, nr);
            const std::uint32_t wn = f_.word[n];
            if (wn == kNoPiece || !same_piece(w, wn)) continue;
            m = undrained(wn) ? mask(away_[n], towards_[n], h) : 2;
          } else {
            if (!same_flat_in_halo(c, row, nc, nr)) continue;
            if (f_.halo_code[halo_.index(nc + 1, nr + 1)] != kNoFlow) {
              m = 2;
            } else if (const RingCell* hc = halo(nc, nr); hc != nullptr) {
              m = mask(hc->away, hc->towards, h);
            }
          }
          if (m < best_mask) {
            best_mask = m;
            best = k;
          }
        }
        d8(c, row) = best >= 0 ? std::uint8_t(best) : kTerminal;
      }
  }

 private:
  static bool undrained(std::uint32_t w) { return w != kNoPiece && (w & kUndrained); }
  static bool same_piece(std::uint32_t a, std::uint32_t b) { return (a & kPieceBits) == (b & kPieceBits); }
  /// A low edge 2; an undrained cell from its distances (see the proof above).
  static std::int32_t mask(std::int32_t away, std::int32_t towards, std::int32_t height) {
    return away < kFar ? height + 1 - away + 2 * towards : 2 + 2 * towards;
  }
  bool inside(int c, int row) const { return c >= 0 && row >= 0 && c < cols_ && row < rows_; }
  std::size_t index(int c, int row) const { return std::size_t(row) * std::size_t(cols_) + std::size_t(c); }
  /// Halo cell (nc, nr) next to the tile's ring cell (c, row) lies in its flat: one elevation, not outside.
  bool same_flat_in_halo(int c, int row, int nc, int nr) const {
    const std::size_t h = halo_.index(nc + 1, nr + 1);
    return !out_code(f_.halo_code[h]) && f_.halo_z[h] == f_.ring_z[ring_.index(c, row)];
  }

  /// Breadth-first distances from `seeds` (distance, tile cell), over the tile's undrained cells
  /// of shared flats, one step between 8-neighbours of one piece; a seed keeps its value.
  std::vector<std::int32_t> distances(std::vector<std::pair<std::int32_t, std::uint32_t>> seeds) const {
    std::vector<std::int32_t> d(f_.word.size(), kFar);
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
      for (const std::uint32_t i : front) {
        const int c = int(i % std::uint32_t(cols_)), row = int(i / std::uint32_t(cols_));
        for (int k = 0; k < 8; ++k) {
          const int nc = c + dcol[k], nr = row + drow[k];
          if (!inside(nc, nr)) continue;
          const std::size_t n = index(nc, nr);
          if (!undrained(f_.word[n]) || !same_piece(f_.word[n], f_.word[i]) || d[n] <= level + 1) continue;
          d[n] = level + 1;
          next.push_back(std::uint32_t(n));
        }
      }
      std::swap(front, next);
    }
    return d;
  }

  const int cols_, rows_;
  const Ring ring_, halo_;
  const FlatCells& f_;
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

template <class T>
void write_values(std::ofstream& out, const std::vector<T>& v) {
  out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(T)));
}
template <class T>
void read_values(std::ifstream& in, std::vector<T>& v) {
  in.read(reinterpret_cast<char*>(v.data()), std::streamsize(v.size() * sizeof(T)));
}

void write_flat_cells(const std::string& path, const FlatCells& f) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  write_values(out, f.word);
  write_values(out, f.ring_z);
  write_values(out, f.halo_z);
  write_values(out, f.halo_code);
  if (!out) throw bad_input(path + ": cannot write scratch data (disk full?)");
}

/// The FlatCells of tile `r` written by write_flat_cells; `pieces` as pass 2 found them.
FlatCells read_flat_cells(const std::string& path, const TileRect& r, const std::vector<FlatPiece>& pieces) {
  FlatCells f;
  f.word.resize(std::size_t(r.cols) * std::size_t(r.rows));
  f.ring_z.resize(Ring(r).size());
  f.halo_z.resize(Ring(window_of(r)).size());
  f.halo_code.resize(f.halo_z.size());
  f.pieces = pieces;
  std::ifstream in(path, std::ios::binary);
  read_values(in, f.word);
  read_values(in, f.ring_z);
  read_values(in, f.halo_z);
  read_values(in, f.halo_code);
  if (!in) throw bad_input(path + ": cannot read scratch data back");
  return f;
}

}  // namespace

// Pass 2, for a tile with cells of flats that reach its halo: the pieces, the outer ring before any
// wave, and the FlatCells kept on a scratch file for the rounds.
void TiledRun::share_tile_flats(int t, const TileRect& r, const Dem& near, const Raster<std::uint8_t>& first,
                                const std::vector<std::uint8_t>& member) {
  FlatCells f = find_flat_cells(r, near, first, member);
  const TileFlats flats(r, f);
  ring_[std::size_t(t)] = flats.ring();
  flat_cells_[std::size_t(t)] = flats.undrained_cells();
  if (flat_cells_[std::size_t(t)] > 0) write_flat_cells(flats_path(t), f);
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
  std::vector<std::uint8_t> solving(flat_cells_.size());
  for (std::size_t t = 0; t < solving.size(); ++t) solving[t] = flat_cells_[t] > 0;
  double ring_bytes = 0;
  for (const auto& ring : ring_) ring_bytes += double(ring.size()) * sizeof(RingCell);
  do {
    ++report_.flat_rounds;
  } while (flat_round(solving));
  release(fresh_ring_);
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
    release(fresh_ring_[std::size_t(t)]);
  }
  bool any = false;
  for (int t = 0; t < tiles_; ++t) {
    const int i = t % grid_.across(), j = t / grid_.across();
    bool next_to_change = false;
    for (int k = 0; k < 8; ++k) {
      const int ni = i + dcol[k], nj = j + drow[k];
      if (ni >= 0 && nj >= 0 && ni < grid_.across() && nj < grid_.down()) next_to_change |= changed[std::size_t(nj * grid_.across() + ni)] != 0;
    }
    solving[std::size_t(t)] = flat_cells_[std::size_t(t)] > 0 && next_to_change;
    any |= solving[std::size_t(t)] != 0;
  }
  return any;
}

void TiledRun::solve_tile_flats(int t, const TileRect& r, std::vector<RingCell>& ring) {
  FlatCells f = read_flat_cells(flats_path(t), r, pieces_[std::size_t(t)]);
  TileFlats flats(r, f);
  flats.solve([&](int c, int row) { return ring_cell(r.col0 + c, r.row0 + row); }, f.pieces);
  ring = flats.ring();
  pieces_[std::size_t(t)] = std::move(f.pieces);
}

// Pass 3's start: the tile's undrained cells of shared flats given their directions.
void TiledRun::direct_tile_flats(int t, const TileRect& r, Raster<std::uint8_t>& d8) const {
  FlatCells f = read_flat_cells(flats_path(t), r, pieces_[std::size_t(t)]);
  TileFlats flats(r, f);
  auto halo = [&](int c, int row) { return ring_cell(r.col0 + c, r.row0 + row); };
  flats.solve(halo, f.pieces);
  flats.direct(d8, [&](std::uint32_t piece) { return flat_height_[flat_of_[piece_base_[std::size_t(t)] + piece]]; }, halo);
}

}  // namespace terrapolis::hydro::tiled
