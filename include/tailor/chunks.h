// tailor: the chunked engine's rule (DESIGN.md section 8, docs/ARCHITECTURE.md "The chunked engine").
//
// A large mesh is cut into chunks by a world grid whose cell side is a power of two in world units:
// a face belongs to the cell that holds its centroid. The grid's planes sit kChunkGridOffset cells
// off the world origin's, so that no plane lies at a round coordinate (a floor scanned at z = 0, a
// wall at x = 10): a noisy surface along a grid plane would have its faces dealt at random between
// the cells on either side (a plane at z = 0 with noise: 16,190 patches instead of 4). The cell side
// comes from the median edge length, rounded to a power of two, so neither the file's order, the
// bounding box nor the thread count moves a chunk border, and a local edit moves none either. A cell
// holding more than ChunkOptions::split_above faces (a folded surface: up to 4x a flat cell's) is
// split into its eight octants, again while a part holds more: the split depends on the cell's own
// faces only, so a local edit changes no other cell's parts, and no worker maps more than about
// split_above faces at once (its memory) nor holds back the others (the balance of the threads).
// map_texture maps each chunk on its own (in parallel) from its own geometry only: the same chunk
// gives the same UVs bit for bit whatever else is loaded and in whatever order its faces, vertices
// and corners come.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "tailor/api.h"
#include "tailor/mesh.h"
#include "tailor/option_doc.h"
#include "tailor/status.h"

namespace tailor {

//! Whether map_texture cuts the mesh into chunks.
enum class ChunkMode : uint8_t {
  kAuto,  //!< chunks from ChunkOptions::min_faces faces on (smaller meshes are one chunk, mapped whole)
  kOn,    //!< always chunks (a small mesh may still fall into one cell)
  kOff,   //!< never: the whole mesh is one chunk, as its own bounding box and principal axis say
};

//! The grid's offset, in cells: cell (i, j, k) spans [(i + offset) side, (i + 1 + offset) side) on x,
//! and so on. sqrt(2) - 1: no dyadic cell side times it is a round number.
inline constexpr double kChunkGridOffset = 0.41421356237309503;

//! Octant levels a cell may be split into (parts of 1/16 of its side at the deepest).
inline constexpr int kMaxChunkSplitLevels = 4;

//! Sentinel of ChunkOptions::cell_exponent: derive it from the mesh's median edge length.
inline constexpr int kAutoCellExponent = -1000;

struct ChunkOptions {
  ChunkMode mode = ChunkMode::kAuto;
  uint32_t min_faces = uint32_t{1} << 17;    //!< kAuto: meshes with fewer faces are mapped whole (one chunk)
  int cell_exponent = kAutoCellExponent;     //!< cell side 2^cell_exponent world units (-60..60), or auto
  float cell_edges = 256.f;                  //!< auto: the cell side is about this many median edges (rounded to a
                                             //!< power of two): ~50k-200k faces per full cell (8..4096)
  uint32_t split_above = uint32_t{1} << 17;  //!< a cell (or part) with more faces is split into its octants
                                             //!< (up to kMaxChunkSplitLevels deep); 0 = never split
};

//! Flags and help of the ChunkOptions a user sets (option_doc.h).
inline constexpr OptionDoc kChunkOptionDocs[] = {
    {"mode", "--chunks",
     "auto: meshes from 131072 faces on are cut into chunks by a world-space grid (a power-of-two cell of about "
     "256 median edges), mapped in parallel, each from its own geometry: the same surface in any file order maps "
     "to the same UVs, and an edit changes only the chunks it touches; smaller meshes are mapped whole. on: always "
     "chunks; off: never (one mapping of the whole mesh, one thread for its growth)"},
    {"cell_exponent", "--chunk-cell",
     "the chunk grid's cell side as a power of two of world units (e.g. 4 = 16 units); default: from the median "
     "edge length"},
    {"split_above", "--chunk-split",
     "a chunk cell holding more faces than this (a folded surface) is cut into its eight octants, again while a part "
     "holds more: bounds each worker's memory (~400 bytes per face of the chunk it maps) and evens out the threads' "
     "work; 0 = never cut"},
};

//! The chunks of one mesh: a CSR list of face ids per chunk, chunks in the order of their cells
//! (z, then y, then x; the parts of a split cell one after the other, octant by octant), faces of a
//! chunk in file order (map_texture sorts them spatially).
struct ChunkPlan {
  int cell_exponent = 0;                       //!< cell side = 2^cell_exponent world units
  double cell_size = 0;                        //!< 2^cell_exponent
  double median_edge = 0;                      //!< median edge length of the mesh (world units) the cell came from
                                               //!< (0 when ChunkOptions::cell_exponent gave the cell: not measured)
  double longest_edge = 0;                     //!< longest edge (world units): faces reach that far beyond their cell
  std::vector<std::array<int32_t, 3>> cells;   //!< per chunk: its cell's integer coordinates (the parts of a
                                               //!< split cell share them)
  std::vector<uint8_t> levels;                 //!< per chunk: 0 = its whole cell, else its part's octant depth
  std::vector<std::array<uint16_t, 3>> parts;  //!< per chunk: its part's place in the cell, in parts of
                                               //!< 2^-level of the side per axis (0 for a whole cell)
  std::vector<uint32_t> chunk_start;           //!< #chunks + 1: offsets into faces
  std::vector<uint32_t> faces;                 //!< #F: face ids grouped by chunk
  size_t chunk_count() const { return cells.size(); }
  //! Chunk c's side, world units: the cell's, halved per level.
  double chunk_size(size_t c) const { return std::ldexp(cell_size, -int{levels[c]}); }
  //! Chunk c's corner (its cell's at the grid offset, plus its part's place), world units.
  std::array<double, 3> chunk_origin(size_t c) const {
    const double part = chunk_size(c);
    std::array<double, 3> o;
    for (size_t k = 0; k < 3; ++k) o[k] = (cells[c][k] + kChunkGridOffset) * cell_size + parts[c][k] * part;
    return o;
  }
  //! Every corner farther than this from an edited face keeps its UVs bit for bit: the cell's
  //! diagonal plus a face's reach beyond its cell on both sides.
  double locality_radius() const { return cell_size * 1.7320508075688772 + 2.0 * longest_edge; }
};

//! Checks the options (mode, cell_exponent in -60..60 or auto, cell_edges in 8..4096). O(1).
TAILOR_API Status check_chunk_options(const ChunkOptions& options);

//! True when map_texture with these options cuts this mesh into chunks (kOn, or kAuto and at least
//! min_faces faces). O(1).
TAILOR_API bool uses_chunks(const ChunkOptions& options, size_t face_count);

//! The chunk rule: the cell side (the option, or 2^round(log2(cell_edges * median edge length))),
//! then each face's cell from its centroid, then each cell of more than split_above faces cut into
//! its octants, recursively (the part of a face: its centroid's octant, clamped into the cell, so a
//! part's faces have their centroids in its box up to rounding). Fails with kInvalidArgument on bad options and
//! kInvalidMesh when the mesh has no face, no edge of positive length, or cells beyond 2^20 per
//! axis (a mesh spanning more than a million cells: give a larger cell). O(F) time (the median by
//! two counting passes), on `threads` threads (0: one per 100k faces, at most the cores and 8; at
//! most one per 65,536 faces; the plan is the same for any count), 12 bytes per face while it runs
//! and 4 in the result.
TAILOR_API Status plan_chunks(const Mesh& mesh, const ChunkOptions& options, ChunkPlan& plan, uint32_t threads = 0);

//! The rule's arithmetic for code that streams a mesh instead of holding it (python -m tailor.tiles
//! partitions a binary PLY block by block): plan_chunks computes with these very functions, so a
//! streamed partition and plan_chunks cannot disagree. `corners` holds 9 floats per face (its three
//! corners' x, y, z).
//! Each face's three edge lengths as plan_chunks measures them (edge k from corner k to k+1), into
//! `lengths` (3 per face; kInvalidArgument when the sizes do not match). O(F).
TAILOR_API Status chunk_edge_lengths(std::span<const float> corners, std::span<float> lengths);

//! The cell exponent plan_chunks derives from a median edge length: round(log2(cell_edges * median))
//! clamped to -60..60, or options.cell_exponent when given. kInvalidMesh when the median is not
//! positive and finite. O(1).
TAILOR_API Status chunk_cell_exponent(double median_edge, const ChunkOptions& options, int& exponent);

//! Each face's cell (x, y, z: the cell of its centroid, side 2^cell_exponent) into `cells` (3 per
//! face). kInvalidMesh when a cell lies beyond 2^20 cells from the origin, as plan_chunks. O(F).
TAILOR_API Status chunk_cells(std::span<const float> corners, int cell_exponent, std::span<int32_t> cells);

}  // namespace tailor
