// The chunked engine (tailor/chunks.h): the chunk rule, and map_texture on chunks: the same UVs for
// the same surface in any order and for any thread count, edits that stay local, quality kept.
#include "tailor/chunks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <tuple>

#include "support/fixtures.h"
#include "tailor/chunked_mapper.h"
#include "tailor/mapping.h"
#include "tailor/stability.h"
#include "tailor/topology.h"

namespace tailor {
namespace {

using test::load_test_mesh;

Mesh chunk_faces(const Mesh& mesh, const ChunkResult& result);  // below

// Chunk options that cut a test mesh (tens of thousands of faces) into a handful of chunks.
MapTextureOptions chunked(int cell_exponent) {
  MapTextureOptions options;
  options.chunks.mode = ChunkMode::kOn;
  options.chunks.cell_exponent = cell_exponent;
  return options;
}

// The cell exponent that gives the mesh `cells_across` cells along its longest side.
int exponent_for(const Mesh& mesh, double cells_across) {
  float lo = INFINITY, hi = -INFINITY;
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    for (size_t k = 0; k < 3; ++k) {
      lo = std::min(lo, mesh.positions[3 * v + k]);
      hi = std::max(hi, mesh.positions[3 * v + k]);
    }
  return static_cast<int>(std::floor(std::log2((double{hi} - lo) / cells_across)));
}

// Face f's centroid, world units.
std::array<double, 3> centroid_of(const Mesh& mesh, uint32_t f) {
  std::array<double, 3> c{};
  for (size_t k = 0; k < 3; ++k) {
    for (size_t j = 0; j < 3; ++j) c[k] += mesh.positions[3 * size_t{mesh.indices[3 * f + j]} + k];
    c[k] /= 3.0;
  }
  return c;
}

TEST(ChunkPlan, EveryFaceIsInTheCellOfItsCentroid) {
  const Mesh mesh = load_test_mesh("fertility.off");
  ChunkOptions options;
  options.mode = ChunkMode::kOn;
  options.cell_exponent = exponent_for(mesh, 3);
  ChunkPlan plan;
  ASSERT_TRUE(plan_chunks(mesh, options, plan).is_ok());
  EXPECT_EQ(plan.cell_size, std::ldexp(1.0, options.cell_exponent));
  ASSERT_GT(plan.chunk_count(), 3u);
  ASSERT_EQ(plan.chunk_start.back(), mesh.face_count());
  std::vector<int> seen(mesh.face_count(), 0);
  for (size_t c = 0; c < plan.chunk_count(); ++c) {
    ASSERT_LT(plan.chunk_start[c], plan.chunk_start[c + 1]) << "an empty chunk";
    if (c > 0) {  // z, then y, then x
      const auto& a = plan.cells[c - 1];
      const auto& b = plan.cells[c];
      EXPECT_LT(std::make_tuple(a[2], a[1], a[0]), std::make_tuple(b[2], b[1], b[0])) << "cells out of order";
    }
    for (uint32_t i = plan.chunk_start[c]; i < plan.chunk_start[c + 1]; ++i) {
      const uint32_t f = plan.faces[i];
      ++seen[f];
      const std::array<double, 3> centroid = centroid_of(mesh, f);
      for (size_t k = 0; k < 3; ++k) {
        EXPECT_GE(centroid[k], (plan.cells[c][k] + kChunkGridOffset) * plan.cell_size - 1e-9);
        EXPECT_LE(centroid[k], (plan.cells[c][k] + 1 + kChunkGridOffset) * plan.cell_size + 1e-9);
      }
    }
  }
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<std::ptrdiff_t>(mesh.face_count()));
  // The automatic cell: a power of two near cell_edges median edges, whatever the mesh's position.
  ChunkOptions automatic;
  ASSERT_TRUE(plan_chunks(mesh, automatic, plan).is_ok());
  EXPECT_GE(plan.cell_size, automatic.cell_edges * plan.median_edge / std::sqrt(2.0));
  EXPECT_LE(plan.cell_size, automatic.cell_edges * plan.median_edge * std::sqrt(2.0));
  EXPECT_GT(plan.locality_radius(), plan.cell_size);
}

// A cell of more faces than split_above is cut into octants (again while a part holds more): each
// part holds the faces whose centroids lie in its box, the parts of a cell follow one another, and
// the cells that were not too full are planned as without the split.
TEST(ChunkPlan, OverFullCellsAreCutIntoOctantsOfTheirOwnFaces) {
  const Mesh mesh = load_test_mesh("horse.ply");
  ChunkOptions options;
  options.mode = ChunkMode::kOn;
  options.cell_exponent = exponent_for(mesh, 1.5);
  options.split_above = 0;
  ChunkPlan whole_cells;
  ASSERT_TRUE(plan_chunks(mesh, options, whole_cells).is_ok());
  options.split_above = 2000;
  ChunkPlan plan;
  ASSERT_TRUE(plan_chunks(mesh, options, plan).is_ok());
  ASSERT_GT(plan.chunk_count(), whole_cells.chunk_count());
  ASSERT_EQ(plan.levels.size(), plan.chunk_count());
  ASSERT_EQ(plan.parts.size(), plan.chunk_count());
  ASSERT_EQ(plan.chunk_start.back(), mesh.face_count());
  EXPECT_GT(int{*std::max_element(plan.levels.begin(), plan.levels.end())}, 1) << "no part was cut again";
  std::vector<int> seen(mesh.face_count(), 0);
  size_t kept = 0;  // cells not cut: the same faces in the same order as without the split
  for (size_t c = 0; c < plan.chunk_count(); ++c) {
    const uint32_t size = plan.chunk_start[c + 1] - plan.chunk_start[c];
    ASSERT_GT(size, 0u) << "an empty part";
    EXPECT_TRUE(size <= options.split_above || plan.levels[c] == kMaxChunkSplitLevels) << c;
    if (c > 0) {
      const auto& a = plan.cells[c - 1];
      const auto& b = plan.cells[c];
      EXPECT_LE(std::make_tuple(a[2], a[1], a[0]), std::make_tuple(b[2], b[1], b[0])) << "cells out of order";
    }
    const double side = plan.chunk_size(c);
    EXPECT_EQ(side, std::ldexp(plan.cell_size, -int{plan.levels[c]}));
    const std::array<double, 3> origin = plan.chunk_origin(c);
    for (uint32_t i = plan.chunk_start[c]; i < plan.chunk_start[c + 1]; ++i) {
      const uint32_t f = plan.faces[i];
      ++seen[f];
      const std::array<double, 3> centroid = centroid_of(mesh, f);
      for (size_t k = 0; k < 3; ++k) {
        EXPECT_GE(centroid[k], origin[k] - 1e-6 * side);
        EXPECT_LE(centroid[k], origin[k] + side + 1e-6 * side);
      }
    }
    if (plan.levels[c] == 0) {
      const auto w = std::find(whole_cells.cells.begin(), whole_cells.cells.end(), plan.cells[c]);
      ASSERT_NE(w, whole_cells.cells.end());
      const size_t u = static_cast<size_t>(w - whole_cells.cells.begin());
      EXPECT_TRUE(std::equal(plan.faces.begin() + plan.chunk_start[c], plan.faces.begin() + plan.chunk_start[c + 1],
                             whole_cells.faces.begin() + whole_cells.chunk_start[u],
                             whole_cells.faces.begin() + whole_cells.chunk_start[u + 1]));
      ++kept;
    }
  }
  EXPECT_GT(kept, 0u) << "every cell was cut: the test no longer tests the cells kept whole";
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<std::ptrdiff_t>(mesh.face_count()));
  options.split_above = 10;
  EXPECT_EQ(plan_chunks(mesh, options, plan).code(), ErrorCode::kInvalidArgument);
}

// The plan is the same for any thread count (each thread takes a range of the faces: its cells,
// counts and writes merge in range order), and the median edge is exactly what std::nth_element
// gives over every face's three lengths.
// A noisy terrain of 500,000 faces: a thread takes at least 65,536 faces, so only a mesh this large
// plans on several. Every edge length differs (a median off by one rank would show).
Mesh noisy_terrain() {
  Mesh mesh = test::grid(500, 500, test::Diagonal::kFalling);
  const auto jitter = [](float x, float y, float seed) {
    const float h = std::sin(x * 12.9898f + y * 78.233f + seed) * 43758.547f;
    return h - std::floor(h) - 0.5f;
  };
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    float* p = &mesh.positions[3 * v];
    const float x = p[0], y = p[1];
    p[0] += 0.3f * jitter(x, y, 0.f);
    p[1] += 0.3f * jitter(x, y, 1.f);
    p[2] = 2.f * std::sin(0.05f * x) * std::cos(0.04f * y) + 0.2f * jitter(x, y, 2.f);
  }
  return mesh;
}

TEST(ChunkPlan, SameForAnyThreadCountWithTheExactMedian) {
  for (const char* name : {"horse.ply", "fertility.off", "a noisy terrain"}) {
    const Mesh mesh = std::string(name) == "a noisy terrain" ? noisy_terrain() : load_test_mesh(name);
    std::vector<float> corners(9 * mesh.face_count()), lengths(3 * mesh.face_count());
    for (size_t i = 0; i < 3 * mesh.face_count(); ++i)
      std::copy_n(&mesh.positions[3 * size_t{mesh.indices[i]}], 3, &corners[3 * i]);
    ASSERT_TRUE(chunk_edge_lengths(corners, lengths).is_ok());
    const float longest = *std::max_element(lengths.begin(), lengths.end());
    auto middle = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
    std::nth_element(lengths.begin(), middle, lengths.end());
    ChunkOptions options;
    options.mode = ChunkMode::kOn;
    options.cell_edges = 64.f;   // several cells
    options.split_above = 2000;  // and parts
    ChunkPlan one;
    ASSERT_TRUE(plan_chunks(mesh, options, one, 1).is_ok());
    EXPECT_EQ(one.median_edge, double{*middle}) << name;
    EXPECT_EQ(one.longest_edge, double{longest}) << name;
    ASSERT_GT(one.chunk_count(), 8u) << name;
    EXPECT_GT(int{*std::max_element(one.levels.begin(), one.levels.end())}, 0) << name << ": no cell was cut";
    // Without the cut, the reference by hand: each face's cell (chunk_cells), faces stably sorted
    // by cell in z, y, x order.
    {
      ChunkOptions whole = options;
      whole.split_above = 0;
      ChunkPlan plan;
      ASSERT_TRUE(plan_chunks(mesh, whole, plan, 3).is_ok());
      std::vector<int32_t> cells(3 * mesh.face_count());
      ASSERT_TRUE(chunk_cells(corners, plan.cell_exponent, cells).is_ok());
      std::vector<uint32_t> faces(mesh.face_count());
      for (uint32_t f = 0; f < faces.size(); ++f) faces[f] = f;
      const auto cell_of = [&](uint32_t f) {
        return std::make_tuple(cells[3 * f + 2], cells[3 * f + 1], cells[3 * f]);
      };
      std::stable_sort(faces.begin(), faces.end(), [&](uint32_t a, uint32_t b) { return cell_of(a) < cell_of(b); });
      EXPECT_EQ(plan.faces, faces) << name;
      for (size_t c = 0; c < plan.chunk_count(); ++c)
        for (uint32_t i = plan.chunk_start[c]; i < plan.chunk_start[c + 1]; ++i)
          ASSERT_EQ(cell_of(plan.faces[i]), std::make_tuple(plan.cells[c][2], plan.cells[c][1], plan.cells[c][0]));
    }
    for (const uint32_t threads : {2u, 3u, 8u, 64u}) {
      ChunkPlan plan;
      ASSERT_TRUE(plan_chunks(mesh, options, plan, threads).is_ok());
      EXPECT_EQ(plan.median_edge, one.median_edge) << name << ", " << threads << " threads";
      EXPECT_EQ(plan.longest_edge, one.longest_edge);
      EXPECT_EQ(plan.cell_exponent, one.cell_exponent);
      EXPECT_EQ(plan.cells, one.cells);
      EXPECT_EQ(plan.levels, one.levels);
      EXPECT_EQ(plan.parts, one.parts);
      EXPECT_EQ(plan.chunk_start, one.chunk_start);
      EXPECT_EQ(plan.faces, one.faces) << name << ", " << threads << " threads";
    }
  }
  // More threads than faces, and one face.
  const Mesh horse = load_test_mesh("horse.ply");
  for (const size_t face_count : {size_t{5}, size_t{1}}) {
    Mesh few;
    few.positions = horse.positions;
    few.indices.assign(horse.indices.begin(), horse.indices.begin() + static_cast<std::ptrdiff_t>(3 * face_count));
    ChunkPlan one, many;
    ASSERT_TRUE(plan_chunks(few, ChunkOptions{}, one, 1).is_ok());
    ASSERT_TRUE(plan_chunks(few, ChunkOptions{}, many, 64).is_ok());
    EXPECT_EQ(many.faces, one.faces);
    EXPECT_EQ(many.chunk_start, one.chunk_start);
    EXPECT_EQ(many.median_edge, one.median_edge);
    EXPECT_EQ(one.chunk_start.back(), face_count);
  }
}

TEST(ChunkPlan, RejectsBadOptionsAndHugeSpans) {
  const Mesh mesh = load_test_mesh("spot.obj");
  ChunkPlan plan;
  ChunkOptions bad;
  bad.cell_exponent = 61;
  EXPECT_EQ(plan_chunks(mesh, bad, plan).code(), ErrorCode::kInvalidArgument);
  bad = ChunkOptions{};
  bad.cell_edges = 2.f;
  EXPECT_EQ(plan_chunks(mesh, bad, plan).code(), ErrorCode::kInvalidArgument);
  ChunkOptions tiny;
  tiny.cell_exponent = -40;  // far more than 2^21 cells across the mesh
  EXPECT_EQ(plan_chunks(mesh, tiny, plan).code(), ErrorCode::kInvalidMesh);
  EXPECT_EQ(plan_chunks(Mesh{}, ChunkOptions{}, plan).code(), ErrorCode::kInvalidMesh);
  EXPECT_TRUE(uses_chunks(ChunkOptions{}, ChunkOptions{}.min_faces));
  EXPECT_FALSE(uses_chunks(ChunkOptions{}, ChunkOptions{}.min_faces - 1));
}

TEST(ChunkedMapping, SameSurfaceInAnotherOrderMapsToTheSameBits) {
  for (const char* name : {"fertility.off", "horse.ply", "fandisk.off", "blobby-3cc.off"}) {
    const Mesh mesh = load_test_mesh(name);
    const MapTextureOptions options = chunked(exponent_for(mesh, 2.5));
    StabilityReport report;
    ASSERT_TRUE(measure_stability(mesh, options, report).is_ok()) << name;
    EXPECT_EQ(report.order_identical_ratio, 1.0) << name;
    EXPECT_LT(report.identical_ratio, 1.0) << name;  // the cut's own chunks change
    // Everything beyond the locality radius keeps its bits (on the scans: the CAD part's longest
    // edges make the radius span the part).
    if (std::string(name) == "fandisk.off" || std::string(name) == "blobby-3cc.off") continue;
    EXPECT_GT(report.corners_beyond_radius, 0u) << name;
    EXPECT_EQ(report.identical_beyond_radius_ratio, 1.0) << name;
  }
  // Mapped whole (a small mesh by default) it keeps its bits too: the whole mesh is mapped in
  // canonical order. An edit there moves the bounding box, the seed and the principal axis.
  for (const char* name : {"fertility.off", "spot.obj", "adis16480.stl"}) {
    const Mesh mesh = load_test_mesh(name);
    StabilityReport report;
    ASSERT_TRUE(measure_stability(mesh, MapTextureOptions{}, report).is_ok()) << name;
    EXPECT_EQ(report.order_identical_ratio, 1.0) << name;
    EXPECT_EQ(report.locality_radius, 0.0) << name;
    EXPECT_EQ(report.identical_beyond_radius_ratio, -1.0) << name;
  }
}

TEST(ChunkedMapping, SameBitsForAnyThreadCountAndQualityKept) {
  const Mesh mesh = load_test_mesh("horse.ply");
  const Topology topology = build_topology(mesh);
  MapTextureOptions options = chunked(exponent_for(mesh, 3));
  options.mapping.threads = 1;
  TextureMap one;
  ASSERT_TRUE(map_texture(mesh, topology, options, one).is_ok());
  EXPECT_GT(one.stats.chunks, 4u);
  EXPECT_GT(one.stats.texels_per_unit, 0.0);
  EXPECT_EQ(one.stats.texels_per_unit, std::exp2(std::round(std::log2(one.stats.texels_per_unit))));
  ASSERT_EQ(one.atlas.corner_uv.size(), 6 * mesh.face_count());
  for (const float x : one.atlas.corner_uv) ASSERT_TRUE(std::isfinite(x));
  for (const uint32_t p : one.atlas.patch) ASSERT_LT(p, one.atlas.patch_count);
  EXPECT_EQ(one.metrics.flipped, 0u);
  EXPECT_LE(one.metrics.l2_stretch, 1.02);
  EXPECT_LE(one.metrics.linf_stretch, 3.0);
  for (const uint32_t threads : {2u, 3u}) {
    options.mapping.threads = threads;
    TextureMap other;
    ASSERT_TRUE(map_texture(mesh, topology, options, other).is_ok());
    ASSERT_EQ(other.atlas.corner_uv.size(), one.atlas.corner_uv.size());
    EXPECT_EQ(std::memcmp(other.atlas.corner_uv.data(), one.atlas.corner_uv.data(),
                          one.atlas.corner_uv.size() * sizeof(float)),
              0)
        << threads << " threads";
    EXPECT_EQ(other.atlas.patch, one.atlas.patch);
  }
}

// Cells cut into parts map as the chunks do: the same bits for any thread count and file order,
// each part from its own geometry, and a cell mapped alone (ChunkedMapper) as inside the mesh.
TEST(ChunkedMapping, CellsCutIntoPartsKeepTheBitsAndTheQuality) {
  const Mesh mesh = load_test_mesh("horse.ply");
  const Topology topology = build_topology(mesh);
  MapTextureOptions options = chunked(exponent_for(mesh, 1.5));
  options.chunks.split_above = 6000;
  options.mapping.threads = 1;
  TextureMap one;
  ASSERT_TRUE(map_texture(mesh, topology, options, one).is_ok());
  EXPECT_GT(one.stats.chunks, 16u);
  EXPECT_EQ(one.metrics.flipped, 0u);
  EXPECT_LE(one.metrics.l2_stretch, 1.02);
  EXPECT_LE(one.metrics.linf_stretch, 3.0);
  options.mapping.threads = 2;
  TextureMap two;
  ASSERT_TRUE(map_texture(mesh, topology, options, two).is_ok());
  EXPECT_EQ(two.atlas.corner_uv, one.atlas.corner_uv);
  EXPECT_EQ(two.atlas.patch, one.atlas.patch);
  StabilityReport report;
  ASSERT_TRUE(measure_stability(mesh, options, report).is_ok());
  EXPECT_EQ(report.order_identical_ratio, 1.0);
  EXPECT_EQ(report.identical_beyond_radius_ratio, 1.0);
  // The most cut cell mapped alone: the same bits as inside the whole mesh.
  ChunkedMapper whole(options, options.chunks.cell_exponent, one.stats.texels_per_unit);
  std::vector<ChunkCell> cells;
  ASSERT_TRUE(whole.set_mesh(mesh, &cells).is_ok());
  ChunkPlan plan;
  ASSERT_TRUE(plan_chunks(mesh, options.chunks, plan).is_ok());
  ChunkCell most = plan.cells[0];
  size_t most_parts = 0;
  for (const ChunkCell& cell : cells) {
    const size_t parts = static_cast<size_t>(std::count(plan.cells.begin(), plan.cells.end(), cell));
    if (parts > most_parts) {
      most_parts = parts;
      most = cell;
    }
  }
  ASSERT_GT(most_parts, 1u);
  const ChunkResult inside = *whole.chunk(most);
  ChunkedMapper streamed(options, options.chunks.cell_exponent, one.stats.texels_per_unit);
  ASSERT_TRUE(streamed.set_chunk(most, chunk_faces(mesh, inside)).is_ok());
  EXPECT_EQ(streamed.chunk(most)->corner_uv, inside.corner_uv);
  EXPECT_EQ(streamed.chunk(most)->patch, inside.patch);
  EXPECT_EQ(streamed.chunk(most)->patch_count, inside.patch_count);
}

// Each chunk places its patches' seeds by their world position modulo the texture's repeat: on a
// plane with one texture direction (a user axis, not along a grid axis, on a grid that does not
// start at a cell corner) the patches of neighbouring chunks differ by whole repeats, so every
// chunk border is an invisible seam.
TEST(ChunkedMapping, ChunkBordersOnAPlaneWithOneDirectionAreInvisible) {
  Mesh mesh = test::grid(160, 120, test::Diagonal::kRising);
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    mesh.positions[3 * v] = 0.37f * mesh.positions[3 * v] - 23.3f;
    mesh.positions[3 * v + 1] = 0.37f * mesh.positions[3 * v + 1] + 12.6f;
  }
  const Topology topology = build_topology(mesh);
  MapTextureOptions options = chunked(exponent_for(mesh, 4));
  options.orientation.axis = AxisSource::kUser;
  options.orientation.user_axis = {1.f, 0.37f, 0.f};
  TextureMap map;
  ASSERT_TRUE(map_texture(mesh, topology, options, map).is_ok());
  EXPECT_GT(map.stats.chunks, 8u);
  EXPECT_GT(map.metrics.seam_edges, 100u);  // the chunk borders
  EXPECT_EQ(map.metrics.seam_invisible_ratio, 1.0);
  EXPECT_EQ(map.metrics.visible_seam_ratio, 0.0);
}

TEST(ChunkedMapping, CancelsAndRefusesWhatNeedsTheWholeMesh) {
  const Mesh mesh = load_test_mesh("fandisk.off");
  const Topology topology = build_topology(mesh);
  MapTextureOptions options = chunked(exponent_for(mesh, 2));
  options.mapping.progress = [](float done) { return done < 0.3f; };
  TextureMap map;
  EXPECT_EQ(map_texture(mesh, topology, options, map).code(), ErrorCode::kCancelled);
  EXPECT_TRUE(map.atlas.corner_uv.empty());
  MapTextureOptions skeleton = chunked(exponent_for(mesh, 2));
  skeleton.orientation.axis = AxisSource::kSkeleton;
  EXPECT_EQ(map_texture(mesh, topology, skeleton, map).code(), ErrorCode::kInvalidArgument);
  // Automatic chunks map such a mesh whole instead.
  skeleton.chunks.mode = ChunkMode::kAuto;
  skeleton.chunks.min_faces = 1000;
  ASSERT_TRUE(map_texture(mesh, topology, skeleton, map).is_ok());
  EXPECT_EQ(map.stats.chunks, 0u);
  EXPECT_EQ(map.atlas.corner_uv.size(), 6 * mesh.face_count());
  // A cell the texel density fills with more pixels than the mapping's scale takes (2^40 units at
  // the fandisk's density): refused with the figure, the cell and what to change, nothing mapped.
  const Status huge = map_texture(mesh, topology, chunked(40), map);
  EXPECT_EQ(huge.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(huge.what().find("pixels per chunk cell of side 2^40 units, outside 0.001 to 1e7"), std::string::npos)
      << huge.what();
  EXPECT_NE(huge.what().find("or map it without chunks (chunks off)"), std::string::npos) << huge.what();
}

// The faces of `result` as a mesh of their own (vertices renumbered, in another order than the
// source's), with face i = result.faces[i].
Mesh chunk_faces(const Mesh& mesh, const ChunkResult& result) {
  Mesh out;
  std::vector<uint32_t> id(mesh.vertex_count(), kInvalid);
  for (const uint32_t f : result.faces)
    for (size_t k = 0; k < 3; ++k) {
      const uint32_t v = mesh.indices[3 * size_t{f} + k];
      if (id[v] == kInvalid) {
        id[v] = static_cast<uint32_t>(out.vertex_count());
        out.positions.insert(out.positions.end(), mesh.positions.begin() + 3 * static_cast<std::ptrdiff_t>(v),
                             mesh.positions.begin() + 3 * static_cast<std::ptrdiff_t>(v) + 3);
      }
      out.indices.push_back(id[v]);
    }
  return out;
}

TEST(ChunkedMapper, AChunkAloneMapsAsInsideTheMeshAndReplacingItTouchesNoOther) {
  const Mesh mesh = load_test_mesh("horse.ply");
  const int exponent = exponent_for(mesh, 3);
  ChunkedMapper whole(MapTextureOptions{}, exponent, 4096.0);
  ASSERT_TRUE(whole.check().is_ok());
  std::vector<ChunkCell> cells;
  ASSERT_TRUE(whole.set_mesh(mesh, &cells).is_ok());
  ASSERT_GT(cells.size(), 4u);
  EXPECT_EQ(whole.cells(), cells);
  size_t faces = 0;
  for (const ChunkCell& c : cells) faces += whole.chunk(c)->faces.size();
  EXPECT_EQ(faces, mesh.face_count());
  // The largest chunk, mapped alone from a mesh of its own faces (another vertex order): the
  // same bits as inside the whole mesh.
  const ChunkCell big = *std::max_element(cells.begin(), cells.end(), [&](const ChunkCell& a, const ChunkCell& b) {
    return whole.chunk(a)->faces.size() < whole.chunk(b)->faces.size();
  });
  const ChunkResult inside = *whole.chunk(big);
  const Mesh alone = chunk_faces(mesh, inside);
  ChunkedMapper streamed(MapTextureOptions{}, exponent, 4096.0);
  ASSERT_TRUE(streamed.set_chunk(big, alone).is_ok());
  const ChunkResult* mapped = streamed.chunk(big);
  ASSERT_NE(mapped, nullptr);
  EXPECT_EQ(mapped->corner_uv, inside.corner_uv);
  EXPECT_EQ(mapped->patch, inside.patch);
  EXPECT_EQ(mapped->patch_count, inside.patch_count);
  // Replacing it (a tenth of its faces removed) changes it and no other chunk.
  std::vector<std::vector<float>> before;
  for (const ChunkCell& c : cells) before.push_back(whole.chunk(c)->corner_uv);
  Mesh edited = alone;
  edited.indices.resize(3 * (alone.face_count() - alone.face_count() / 10));
  ASSERT_TRUE(whole.set_chunk(big, edited).is_ok());
  for (size_t i = 0; i < cells.size(); ++i) {
    if (cells[i] == big)
      EXPECT_NE(whole.chunk(cells[i])->corner_uv, before[i]);
    else
      EXPECT_EQ(whole.chunk(cells[i])->corner_uv, before[i]);
  }
  // Faces of another cell are refused, and the chunk keeps what it had.
  const ChunkCell other = cells[0] == big ? cells[1] : cells[0];
  const Status wrong = whole.set_chunk(other, edited);
  EXPECT_EQ(wrong.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(wrong.message().find("outside the chunk's cell"), std::string::npos) << wrong.message();
  EXPECT_EQ(whole.chunk(other)->corner_uv, before[cells[0] == big ? 1 : 0]);
  // A cell 2^21 away (beyond the grid's +-2^20) is no other cell: cells are kept in 21 bits each.
  const ChunkCell aliased{big[0] + (1 << 21), big[1], big[2]};
  EXPECT_EQ(whole.chunk(aliased), nullptr);
  EXPECT_FALSE(whole.remove_chunk(aliased));
  EXPECT_TRUE(whole.remove_chunk(big));
  EXPECT_FALSE(whole.remove_chunk(big));
  EXPECT_EQ(whole.chunk(big), nullptr);
  EXPECT_EQ(whole.cells().size(), cells.size() - 1);
  EXPECT_EQ(ChunkedMapper(MapTextureOptions{}, exponent, 0.0).check().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(ChunkedMapper(MapTextureOptions{}, 70, 1.0).set_mesh(mesh).code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace tailor
