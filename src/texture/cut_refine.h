// Coarse-to-fine tiling: the quilting plan (which exemplar block goes where, in which order) is
// found on a reduced copy of the exemplar (tiling.cpp), then replayed at full size here: each
// block's rectangle and source are scaled up, the source is refined by a masked SSD search within
// a few px of the scaled one (the reduced image placed it only to within one reduced pixel), and
// the minimum-error boundary cut is recomputed at full size inside the scaled overlap, a narrow
// band along the reduced cut. The result is a source map (which exemplar pixel each tile pixel
// shows); compose() applies it to every map of a set, so all maps share one cut and one set of
// offsets and stay registered.
#pragma once

#include <cstdint>
#include <vector>

#include "tailor/image.h"
#include "tailor/tiling.h"
#include "texture/quilting.h"

namespace tailor::internal {

//! One quilting run of the plan: the canvas's known and locked pixels before the first block
//! (reduced size, row-major) and the blocks in the order placed, with the overlap they used.
struct SessionRecord {
  std::vector<uint8_t> known, locked;
  std::vector<Placement> placements;
  int overlap = 0;
};

//! The plan of a tile and its variants on the reduced exemplar: sessions[0] is the base tile
//! (its canvas starts as the exemplar shifted by (shift_x, shift_y)), sessions[k] variant k (its
//! canvas starts as the base tile).
struct TilePlan {
  int width = 0, height = 0;
  int shift_x = 0, shift_y = 0;
  std::vector<SessionRecord> sessions;
};

//! Full-size guide of the cut: `channels` 8-bit samples per pixel, the layout of image.h.
struct Guide {
  const uint8_t* px = nullptr;
  int width = 0, height = 0, channels = 0;
};

//! Replays plan sessions at full size over a guide; see the top of this file.
class CutRefiner {
 public:
  CutRefiner(const Guide& guide, int plan_width, int plan_height);

  //! Full-size coordinate of reduced coordinate v along x (y): floor(v * W / w + 1/2), any integer v.
  int map_x(int v) const { return scale(v, guide_.width, plan_w_); }
  int map_y(int v) const { return scale(v, guide_.height, plan_h_); }

  //! Chooses the full-size wrap of the base tile (its columns start at the guide's column
  //! shift_x(), its rows at shift_y()). One boundary of the plan stands for about W / w boundaries
  //! of the guide, which differ at full size (a JPEG's 8 x 8 block grid, which the exact scale 8 of
  //! a 4096 px photo hits every time; fine lines): of the guide's column boundaries (x - 1, x)
  //! within half a plan pixel of the planned one, the one whose mean absolute difference is
  //! closest (in log ratio) to the median over all columns, as choose_shift picks the planned one;
  //! rows likewise. Every candidate lies inside the plan's repaired zone, whose blocks are
  //! replayed over it. O(N). Without a call, replay uses the planned boundary scaled.
  void choose_wrap(int plan_shift_x, int plan_shift_y);
  int shift_x() const { return shift_x_; }
  int shift_y() const { return shift_y_; }

  //! Replays session `s` of `plan` (base tile: the canvas starts as the guide shifted by
  //! (shift_x(), shift_y()); a variant: as `base`, the base tile's source map). radius: the
  //! refinement search (px).
  void replay(const TilePlan& plan, size_t s, const std::vector<int32_t>* base, int radius);

  //! Exemplar pixel index (y * W + x) shown by each tile pixel.
  const std::vector<int32_t>& source() const { return source_; }

 private:
  static int scale(int v, int full, int reduced) {
    const int64_t n = 2 * static_cast<int64_t>(v) * full + reduced, d = 2 * static_cast<int64_t>(reduced);
    return static_cast<int>(n >= 0 ? n / d : -((-n + d - 1) / d));
  }
  //! Full-size mask of a reduced one: the reduced pixel whose scaled cell holds each full pixel.
  void upsample(const std::vector<uint8_t>& reduced, std::vector<uint8_t>& full) const;
  void place(const Placement& p, int overlap, int radius);

  Guide guide_;
  int plan_w_, plan_h_;
  int shift_x_ = -1, shift_y_ = -1;  // the base tile's wrap (choose_wrap), -1: the plan's scaled
  std::vector<int> cell_x_, cell_y_;
  std::vector<int32_t> source_;
  std::vector<uint8_t> known_, locked_, take_new_;
  std::vector<int32_t> templ_;  // guide samples of the block's known pixels, -1 where unknown
  std::vector<float> error_, strip_, cost_;
  std::vector<int> path_;
};

//! Minimum-error path through a strip of `length` x `width` errors (err[i * width + j], i along the
//! strip): one j per i, |j(i) - j(i-1)| <= 1. Dynamic programming, ties to the smaller j.
void min_error_path(const std::vector<float>& err, int length, int width, std::vector<float>& cost,
                    std::vector<int>& path);

//! How a map's samples are blended where the feather mixes two sources.
enum class BlendKind { kScalar, kNormal };

//! out = the map gathered through `source` (out(p) = in(source[p])); within `feather` px of a
//! cut (where the window of (2 feather + 1)^2 pixels holds more than one offset source - p), the
//! sample is the window's mean of in(p + offset) over its pixels' offsets (Scalar: per channel;
//! Normal: the first three channels as a vector in [-1, 1], renormalised; every output normal
//! is renormalised). Samples are T (uint8_t or uint16_t) with maximum `max_value`.
template <typename T>
void compose(const T* in, int width, int height, int channels, int max_value, BlendKind kind,
             const std::vector<int32_t>& source, int feather, std::vector<T>& out);

//! A quarter-turn tile (symmetry 4) as quilted on a guide, for reading any registered map at full
//! size (read_quarter_turn): per pixel of the n x n quilted tile (before the wrap's roll) its
//! source, turn t * s^2 + y_t * s + x_t in the t-th quarter turn of the s x s exemplar it was
//! quilted from (the guide's reduced copy above kPlanMaxSide, else the guide); the full square
//! exemplar (side full_side, at crop_x, crop_y in the input), the tile's side and the wrap's roll.
struct QuarterTurnPlan {
  std::vector<int32_t> source;
  int n = 0, s = 0;
  int full_side = 0, crop_x = 0, crop_y = 0;
  int tile_side = 0;
  int roll = 0;  //!< tile(x, y) = pinwheel((x + roll) % N, (y + roll) % N)
};

//! A source-map entry's image under the canvas's quarter turn r(x, y) = (n - 1 - y, x): the same
//! exemplar pixel in the next turn, (x_t, y_t) -> (side - 1 - y_t, x_t).
inline int32_t next_turn_source(int32_t src, int side) {
  const int32_t plane = side * side, t = src / plane, x = src % plane % side, y = src % plane / side;
  return ((t + 1) % 4) * plane + x * side + (side - 1 - y);
}

//! The quarter-turn tile of one map (samples T in [0, max_value], interleaved, `width` wide, at
//! least the plan's square) read at full size through `plan` into out (tile_side^2 x channels).
//! Within a block the offset between a tile pixel and its source is constant, so a quilted pixel x
//! with source x_t puts the full map's pixel X + round((x_t - x) * S / s) (of its t-th turn) at
//! full-size X. Each full-size pixel blends what the four quilted pixels nearest to it put there,
//! with bilinear weights: inside a block the four agree and the map's pixel comes out unchanged;
//! across a cut the two blocks cross-fade over S / s px instead of stepping along the quilted cut.
//! The top-left quadrant is read so and the others are its quarter turns (the tile is exactly
//! 4-fold), then rolled. normal: the first three channels are a tangent-space normal (+x right,
//! +y up as glTF, or down with y_down as DirectX), turned with the content (a quarter turn r takes
//! (x, y) to (y, -x), with y_down to (-y, x)), blended as vectors and renormalised. O(N^2).
template <typename T>
void read_quarter_turn(const T* in, int width, int channels, double max_value, bool normal, bool y_down,
                       const QuarterTurnPlan& plan, std::vector<T>& out);

//! The quilting of tiling.cpp (make_tile_variants for images up to kPlanMaxSide) on `exemplar`,
//! recording its plan in `plan` (may be null). all_channels: the block search uses every channel
//! (a map set's guide) rather than a colour image's luminance.
//! With symmetry 4, quarter_plan (may be null) receives the tile's QuarterTurnPlan.
Status plan_tile_variants(const Image& exemplar, const TileOptions& options, int count, bool all_channels,
                          std::vector<Image>& tiles, TileReport* report, TilePlan* plan,
                          QuarterTurnPlan* quarter_plan = nullptr);

}  // namespace tailor::internal
