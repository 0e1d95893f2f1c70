// tailor: self-tileable textures (thesis chapter 3).
//
// make_tileable() turns a texture photograph into a tile whose right edge continues its left edge
// and whose bottom edge continues its top edge, so that it can be repeated without visible seams:
//   1. swap the quadrants (toroidal shift by about half the size: the new wrap is put on the
//      interior column / row within 1/8 of the middle whose difference is closest to the median
//      one, so it is as ordinary as any other); the old wrap seams now form a '+' inside;
//   2. repair the vertical arm of the '+' (a strip of width block/2 - overlap, treated as a ring
//      through the top/bottom border), then the horizontal arm, then the centre, by image quilting
//      (Efros & Freeman 2001) from the exemplar with half-size blocks (block/2, overlap/2): blocks
//      within `tolerance` of the best SSD over their overlap (colour searched in luminance), of
//      which up to 32 drawn at random (seeded) are ranked by the 7 x 7 patches their
//      minimum-error boundary cuts would create (distance to the exemplar patches their pixels
//      came from, i.e. what the patch-coherence metric charges); a tolerance set of fewer than 8
//      blocks is topped up with the next best by SSD so that the ranking has a choice.
//      On exemplars whose strongest interior edge decides the worst seam (interior worst > 2 x
//      median), that edge is kept verbatim, so its ratio must not rise at all: there smooth
//      blocks are penalised and each arm's blocks are also ranked by how much they smooth the
//      straight row (column) boundaries they cross, or strengthen a strong one, against the
//      shifted exemplar (tops up to 16 blocks); if the worst seam still misses, the vertical arm
//      is redone without that check. On the other exemplars, images under 226 x 226 px get 2 to
//      4 attempts (floor(320^2 / pixels)) with derived random streams (kept: the one meeting the
//      worst-seam target with the lowest total cut cost), and a smooth-block penalty is a last
//      try when none meets it.
//      Pixels outside the repaired strips stay bit-exact copies of the shifted exemplar.
// make_tile_variants() adds tiles whose outer ring (TileReport::border px) is bit-identical to the
// first one while the interior is re-quilted with 2 x 2 large blocks, so they can be mixed for
// aperiodic tiling (thesis 3.2).
// With fit_period the exemplar is first cropped or extended (never resampled: texels keep their
// size) to a whole number of texel periods, extension copying the texture one period back, so
// that a regular pattern ends in phase (thesis 3.1: 10 px stripes in 55 px -> 60 px).
//
// With symmetry = 4 the tile is also unchanged by a quarter turn up to a shift: a square N x N
// tile (S = the exemplar's smaller side rounded down to a multiple of 4, a non-square exemplar
// cropped to its centred square; N = 2S up to 2048 px, else, or with same_size, N = S) built as a
// pinwheel of one N/2 x N/2 quadrant (the whole exemplar, or with N = S the exemplar square of 3 x 3
// places whose histogram is nearest the whole's) and its three quarter turns, whose seams are
// repaired by the same quilting, drawing blocks from the exemplar's four turns and writing every
// block into all four rotated places (the rotation centres get one wedge-shaped block each), the
// wrap put on the better of the two repaired '+' lines (a retry with the smooth-block penalty when
// its ratio misses [0.8, 1.2]): rot90(tile)(x, y) = tile(y, N-1-x) equals tile(x, y) exactly, i.e.
// the tile is unchanged by a quarter turn about its centre and corner (where the 4-fold map turns
// it). Its patch coherence is about 1.1-1.2 x the exemplar's with N = 2S, 2-2.5 x with N = S (see
// docs/tiling.md). Exemplars above kPlanMaxSide are quilted so on a kPlanSide px copy and the tile
// is read at full size from that tile's source map (each block at the photo's own resolution,
// cross-fades of the scale factor's width across the cuts): a 4096 px photo in ~1.5 s.
//
// Images follow the layout of image.h (1 to 4 channels; alpha is just a channel, except that the
// FFT search of 3- and 4-channel images runs on the RGB luminance; the ranking uses all channels).
// Cost: O(blocks * N log N) for an N-pixel exemplar (one FFT correlation per block); about 0.6 s
// for a 512 x 512 RGB or grey exemplar on one core, twice that when a second try is needed; about
// 0.07 s for 128 x 128 (several attempts). Memory: a few float copies of the exemplar plus up to 8
// FFT spectra. Images above kPlanMaxSide (640 px) are planned on a 512 px copy and replayed at full
// size (see kPlanMaxSide): 2048 x 2048 in ~0.8 s, 4096 x 4096 in ~2.5 s, about 10 bytes a pixel
// besides the input and output. With auto_period (default) a strongly periodic exemplar is tiled
// twice (plain and period-fitted).
// Deterministic: same input + options -> bit-identical output. Safe for untrusted images (sizes
// are checked; nothing is assumed about the pixel values).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tailor/api.h"
#include "tailor/image.h"
#include "tailor/option_doc.h"
#include "tailor/status.h"

namespace tailor {

//! Called with the fraction done in [0, 1]; returning false cancels (the call returns kCancelled).
using TileProgress = std::function<bool(double)>;

struct TileOptions {
  int block = 32;   //!< quilting block side in px, [8, 256]; shrunk to min(W, H) / 4 (with a warning) for small images;
                    //!< the '+' is repaired with blocks of max(8, block / 2), variants with large blocks
  int overlap = 0;  //!< overlap of neighbouring blocks in px, [1, block / 2 - 1]; 0 = block / 4
  uint64_t seed = 1;        //!< seeds the random choice among near-best blocks; same seed -> same tile
  double tolerance = 0.1;   //!< candidate blocks have SSD <= best * (1 + tolerance), [0, 1]
  bool fit_period = false;  //!< crop/extend to a whole number of texel periods first (thesis 3.1)
  bool auto_period =
      true;          //!< without fit_period: when a strong period is detected (confidence >= kStrongPeriod),
                     //!< also make the period-fitted tile and keep it unless it misses a target the plain one meets
  int symmetry = 1;  //!< 1: plain tile; 4: also unchanged by a quarter turn (square output, one tile,
                     //!< no fit_period; see make_tileable)
  bool same_size = false;  //!< symmetry 4: a tile of the input's (cropped) side, each quadrant a quarter
                           //!< of it, instead of twice the side with the whole input in each quadrant
  TileProgress progress;   //!< optional progress callback (may be empty)
};

//! Flags and help of the TileOptions a user sets (option_doc.h).
inline constexpr OptionDoc kTileOptionDocs[] = {
    {"block", "--block", "Quilting block size in px"},
    {"overlap", "--overlap", "Block overlap in px (when not given: block/4)"},
    {"seed", "--seed", "Seed of the random block choice (same seed, same output)"},
    {"fit_period", "--fit-period", "Crop or extend to a whole number of texel periods (regular patterns)"},
    {"auto_period", "--no-auto-period",
     "Do not fit a strongly periodic texture (bricks, tiles, planks) to its period by default (auto: the fitted tile "
     "is kept unless it misses a seam or histogram target the plain one meets)"},
    {"symmetry", "--symmetry",
     "1 or 4: 4 makes a square tile that is also unchanged by a quarter turn (rot90(tile) == tile), for "
     "stochastic textures (gravel, sand, bark, moss); directional ones (bricks, planks, grain) cannot look "
     "the same turned and get a warning. The tile is twice the input's side (its square crop; inputs over "
     "1024 px keep their side), each quadrant the whole input turned; with --set every map through one cut, "
     "normal maps turned with their content. Not with --variants or --fit-period"},
    {"same_size", "--same-size",
     "With --symmetry 4: a tile of the input's side, each quadrant a quarter of it (more seams per pixel: "
     "patch coherence about 2x worse than the default's twice-the-side tile)"},
};

//! Texel period found by autocorrelation (thesis 3.1), per axis.
struct PeriodEstimate {
  double period_x = 0.0;      //!< px, sub-pixel; 0 when no period was found along x
  double period_y = 0.0;      //!< px, sub-pixel; 0 when no period was found along y
  double confidence_x = 0.0;  //!< [0, 1]: height of the autocorrelation peak above the dip before it
  double confidence_y = 0.0;  //!< same along y
  bool found_x = false;       //!< confidence_x passed the threshold and period_x is meaningful
  bool found_y = false;
};

//! What make_tileable did, for reports and the variants' JSON.
struct TileReport {
  int width = 0;  //!< output size (differs from the input with fit_period, and with symmetry 4: twice its side)
  int height = 0;
  int block = 0;            //!< block side actually used (px)
  int overlap = 0;          //!< overlap actually used (px)
  int border = 0;           //!< width of the outer ring that is bit-identical across variants (px)
  int shift_x = 0;          //!< toroidal shift used: tile(x, y) = input((x + shift_x) % W, (y + shift_y) % H)
  int shift_y = 0;          //!<   outside the repaired strips (about W/2, H/2; see make_tileable); 0 with symmetry 4
  int symmetry = 1;         //!< TileOptions::symmetry as used
  double anisotropy = 0.0;  //!< symmetry 4: orientation_anisotropy() of the exemplar (> 0.5 warns)
  int quarter_turn_difference = -1;   //!< symmetry 4: quarter_turn_difference() of the tile (0: exact)
  int blocks = 0;                     //!< quilting blocks placed (all variants)
  PeriodEstimate period;              //!< filled when fit_period was asked for, or auto_period found a strong one
  bool period_fitted = false;         //!< the output was fitted to the period (fit_period, or auto_period chose it)
  std::vector<std::string> warnings;  //!< e.g. "block shrunk from 32 to 16 px for a 64 px image"
};

//! Toroidal shift by (width / 2, height / 2): out(x, y) = in((x + width/2) % width, (y + height/2) % height).
//! The input's wrap seams end up on column width - width/2 and row height - height/2.
TAILOR_API Image swap_quadrants(const Image& image);

//! Makes `exemplar` self-tileable (see the top of this file). `tile` has the exemplar's channel count
//! and size (or the period-fitted size). Fails with kInvalidImage for an inconsistent image or one
//! smaller than 32 px a side, kInvalidArgument for options out of range, kCancelled when progress
//! returned false. `report` may be null.
TAILOR_API Status make_tileable(const Image& exemplar, const TileOptions& options, Image& tile,
                                TileReport* report = nullptr);

//! `count` tiles (1 to 64): tiles[0] is make_tileable's result, tiles[k] re-quilts everything but
//! the outer TileReport::border px ring with 2 x 2 large blocks, seed (options.seed, k), a raster
//! order that changes with k, and tiles[0]'s own source blocks excluded (so interiors differ).
//! All tiles share that ring bit-exactly, so any of them can be placed next to any other.
//! Cost: make_tileable plus 4 FFT block searches per extra tile.
TAILOR_API Status make_tile_variants(const Image& exemplar, const TileOptions& options, int count,
                                     std::vector<Image>& tiles, TileReport* report = nullptr);

//! One map of a material set (make_tileable_set).
struct TileMap {
  Image16 image;         //!< 8- or 16-bit, 1 to 4 channels (alpha is a channel like any other)
  bool normal = false;   //!< a normal map: blended as unit vectors (the first three channels), renormalised
  bool directx = false;  //!< a normal map whose +y points down the image (DirectX; glTF's points up): with
                         //!< symmetry 4 its vectors turn the other way round
};

//! Makes a set of registered maps (colour, normal, roughness, height...) self-tileable together:
//! one plan of cuts found on a guide holding one channel per map (luminance of colour maps, the
//! sample of grey ones; more than four maps share channels), so the seam search weighs every map,
//! and the same cut and source offsets applied to every map, so the outputs stay registered.
//! tiles[k][m] is variant k (as make_tile_variants) of map m, with its bit depth and channels.
//! Within max(1, scale / 2) px of a cut (scale: full size / plan size, see kPlanMaxSide) the
//! sources of both sides are blended: scalar maps per channel, normal maps as vectors; every
//! output normal is renormalised. Small sets are planned at full size (scale 1, 1 px feather). With
//! symmetry 4 one quarter-turn tile is quilted on the guide (make_tileable's, on a kPlanSide px
//! copy above kPlanMaxSide) and every map is read through its source map at full size, normal
//! maps turned with their content (+x right, +y up, as glTF) and renormalised. Fails with
//! kInvalidArgument for an empty set, maps of different sizes (saying which), or what
//! make_tile_variants refuses.
TAILOR_API Status make_tileable_set(const std::vector<TileMap>& maps, const TileOptions& options, int count,
                                    std::vector<std::vector<Image16>>& tiles, TileReport* report = nullptr);

//! The file name a tiled map of a set is written under (`tailor tile --set`, tailor.tile_set): the
//! input's file name, its extension replaced by .png ("maps/bark_color.jpg" -> "bark_color.png").
TAILOR_API std::string tile_set_file_name(const std::string& input_path);

//! Images whose larger side exceeds this are tiled coarse-to-fine: the quilting plan is found on
//! a copy reduced to kPlanSide px (the larger side; the block, overlap and search are those of a
//! kPlanSide px image), then replayed at full size with each block's source refined within
//! (scale / 2 + 1) px and its cut recomputed inside the scaled overlap.
inline constexpr int kPlanMaxSide = 640;
//! auto_period: an axis whose period confidence reaches this is strongly periodic (shared photos:
//! VisTex tile 0.56 / 0.66, fabric 0.47 along x; brick 0.23, the stochastic ones below 0.1).
inline constexpr double kStrongPeriod = 0.3;
inline constexpr int kPlanSide = 512;

//! Largest absolute 8-bit sample difference between rot90(tile) (a quarter turn) and the tile
//! shifted toroidally by the best of (0 | N/2, 0 | N/2): 0 for a tile that is exactly unchanged by
//! a quarter turn about its centre or its corners (shift 0) or about the centre of a quadrant.
//! The shift found is returned in shift_x / shift_y when not null. -1 for a non-square or invalid
//! image. O(N).
TAILOR_API int quarter_turn_difference(const Image& tile, int* shift_x = nullptr, int* shift_y = nullptr);
//! The largest quarter_turn_difference that still counts as the same tile with symmetry 4 (`tailor
//! map`'s warning, `tailor render`'s seams view): JPEG compression of a symmetric tile leaves a few
//! levels.
inline constexpr int kQuarterTurnNoiseLevels = 12;

//! How directional an image is, in [0, 1]: the coherence of its structure tensor summed over the
//! image, |sum w e^{2i theta}| / sum w over the luminance gradients (weight w = squared gradient
//! magnitude, theta its angle). 0 when the gradient orientations are as common as their quarter
//! turns, 1 for parallel lines (stripes, planks). Shared photos: VisTex tile 0.01, gravel 0.05,
//! grass 0.16, bark 0.20, water 0.21, fabric 0.24, sand 0.40 (ripples), brick 0.62. A quarter
//! turn negates the sum, so a texture with a high value cannot look the same turned; symmetry 4
//! warns above 0.5. O(N).
TAILOR_API double orientation_anisotropy(const Image& image);

//! Texel period along x and y from the normalised (unbiased) autocorrelation of the luminance,
//! computed by FFT: the first autocorrelation peak within lags [3, 2 size / 3] reaching 80 % of the
//! highest one, refined to sub-pixel by a parabola. Noise-like textures give found = false.
//! Cost O(N log N). Never fails (an invalid image gives an empty estimate).
TAILOR_API PeriodEstimate estimate_period(const Image& image);

//! Size holding a whole number of periods nearest (width, height): n = floor(size / period + 0.55)
//! periods (ties go to the larger size: the thesis prefers adding texture to cutting it), at least
//! one; axes without a period keep their size. Results are clamped to [32, kMaxImageSide].
TAILOR_API void period_fitted_size(const PeriodEstimate& period, int width, int height, int& fitted_width,
                                   int& fitted_height);

//! Quality of a tile (thesis ch. 4 and issue 4). Column boundary x is the pair (x, x+1 mod W);
//! its "difference" is the mean absolute 8-bit difference across it over all rows and channels.
struct TileMetrics {
  double wrap_ratio_x = 0.0;  //!< difference across the wrap column / median interior column difference (~1 seamless)
  double wrap_ratio_y = 0.0;  //!< same for rows
  double worst_seam_ratio = 0.0;  //!< max over all column and row boundaries, wrap included, of difference / median
  double gradient_energy = 0.0;   //!< mean |dx| + |dy| over interior pixels and channels (8-bit units)
  bool has_exemplar = false;      //!< the fields below are filled only when an exemplar was given
  double exemplar_worst_seam_ratio = 0.0;  //!< the exemplar's own worst interior boundary ratio (wrap excluded)
  double exemplar_wrap_ratio_x = 0.0;      //!< the exemplar's wrap ratios (how non-tileable it was)
  double exemplar_wrap_ratio_y = 0.0;
  double histogram_l1 = 0.0;     //!< sum |p - q| of 64-bin normalised histograms, mean over channels, [0, 2]
  double gradient_ratio = 0.0;   //!< gradient_energy of the tile / of the exemplar (< 1: blurred or ghosted)
  double patch_coherence = 0.0;  //!< mean over 7x7 tile patches (read toroidally) of the per-sample squared distance
                                 //!< to the nearest exemplar patch, over the exemplar's variance (0 = all copied)
  double exemplar_patch_coherence = 0.0;  //!< the same for the exemplar itself read toroidally (baseline)
  int quarter_turn_difference =
      -1;  //!< quarter_turn_difference() of the tile (0: unchanged by a quarter turn; -1 not square)
  int quarter_turn_shift_x = 0;  //!< the shift it found (0 or N/2)
  int quarter_turn_shift_y = 0;
  bool coherence_with_turns = false;  //!< both coherences were measured against the exemplar and its three
                                      //!< quarter turns (done when quarter_turn_difference == 0: such a tile
                                      //!< holds every patch in four orientations by construction)
};

//! Computes TileMetrics of `tile`, comparing with `exemplar` when it is not null (channel counts may
//! differ: both are then compared in luminance). Patch coherence: tile patches on a fixed grid
//! (stride 1 up to 128 x 128 px, else the smallest stride giving <= 16384 patches; the last patch
//! of each row and column straddles the wrap, so the wrap seam is always sampled); patches copied
//! verbatim are found exactly by hashing every exemplar patch, the others by PatchMatch (Barnes et
//! al. 2009, constant seed, 6 iterations), so the value is an upper bound of the exact one, and
//! deterministic. A tile exactly unchanged by a quarter turn (quarter_turn_difference 0) is compared
//! with the exemplar in its four quarter turns (the nearest patch over the four), and so is the
//! exemplar's own baseline. Cost: O(N) plus ~0.1 s per 512 px image (4 x for such a tile). Fails with kInvalidImage for
//! an inconsistent image or one smaller than 8 px a side. Safe for untrusted images.
TAILOR_API Status tile_metrics(const Image& tile, const Image* exemplar, TileMetrics& metrics);

//! The wrap ratios of tile_metrics alone (TileMetrics::wrap_ratio_x / _y: the difference across the
//! wrap column / row over the median interior one; ~1 seamless, eval-tile's target [0.8, 1.2]), for
//! the check `tailor map` makes of its texture. O(pixels), one pass. Fails with kInvalidImage like
//! tile_metrics (inconsistent, or smaller than 8 px a side).
TAILOR_API Status wrap_ratios(const Image& tile, double& x, double& y);
//! The upper end of eval-tile's wrap-ratio target: above it, the wrap shows as a cut.
inline constexpr double kWrapRatioSeamless = 1.2;

//! The quality targets: wrap ratios in [0.8, 1.2], worst seam <= max(exemplar's, 1.5),
//! histogram L1 <= 0.1, gradient ratio >= 0.95, patch coherence <= the exemplar's toroidal one
//! (no allowance). Returns true when all hold; `failed` lists the others.
TAILOR_API bool meets_tile_targets(const TileMetrics& metrics, std::string* failed = nullptr);

//! The targets of meets_tile_targets that `metrics` misses, one entry each with its figure and
//! limit, e.g. "wrap ratio x 1.61 outside [0.8, 1.2]" or "worst seam 6.71 above 6.52 (the
//! exemplar's 6.52, at least 1.5)"; empty when every target is met (what `tailor tile` prints on
//! stderr, one line per entry).
TAILOR_API std::vector<std::string> missed_tile_targets(const TileMetrics& metrics);

}  // namespace tailor
