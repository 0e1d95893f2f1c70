// An EditSession on a chunked mesh (chunk_edit.h).
#include "edit/chunk_edit.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <system_error>
#include <thread>

#include "mapping/mapping_common.h"
#include "surface/orientation_setup.h"
#include "surface/stroke_field.h"

namespace tailor::internal {
namespace {

// Canonical forms kept: the chunks a user paints on in a row (a brush band across a body crosses
// several; a chunk keeps about 180 bytes per face: its mesh, topology, frames, atlas and scratch).
constexpr size_t kKeptChunks = 8;

// A stroke's reach as the touched test takes it: its radius grown by this share (the faces' centroids
// are summed in another corner order there than in the field's lookup: a few ulps).
constexpr double kReachMargin = 1e-3;

// The options map_chunk maps chunk `chunk` with (chunk_map_options), with its seam faces.
MapTextureOptions chunk_options(const ChunkedEdits::Layout& layout, const MapTextureOptions& options, uint32_t chunk,
                                std::span<const uint8_t> seam) {
  MapTextureOptions o = chunk_map_options(options, layout.plan.chunk_origin(chunk), layout.plan.chunk_size(chunk),
                                          layout.texels_per_unit);
  o.mapping.seam_faces = seam;
  return o;
}

// Runs body(i) for i in [0, n) on up to `threads` threads (0: the cores), each i on one thread:
// the chunks an edit touches are independent, so the result does not depend on the count.
template <class Body>
void for_each_index(size_t n, uint32_t threads, Body body) {
  const size_t cores = std::max<size_t>(std::thread::hardware_concurrency(), 1);
  const size_t count = std::min<size_t>(n, threads ? threads : cores);
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t i; (i = next.fetch_add(1)) < n;) body(i);
  };
  std::vector<std::thread> workers;
  try {
    for (size_t t = 1; t < count; ++t) workers.emplace_back(work);
  } catch (const std::system_error&) {  // no thread to be had: the calling thread does the rest
  }
  work();
  for (std::thread& t : workers) t.join();
}

std::span<const uint32_t> chunk_faces(const ChunkPlan& plan, uint32_t chunk) {
  return {plan.faces.data() + plan.chunk_start[chunk], plan.chunk_start[chunk + 1] - plan.chunk_start[chunk]};
}

}  // namespace

struct ChunkedEdits::Kept {
  uint32_t chunk = 0;
  uint64_t used = 0;
  ChunkWorker w;  // canonical mesh, faces, seam flags; map: frames and atlas (chunk patch ids)
  Topology topology;
  LocalUpdate local;
};

bool session_uses_chunks(const MapTextureOptions& options, size_t face_count) {
  // As map_texture decides: the skeleton axis needs the whole mesh (auto maps it whole).
  const bool whole_only = options.chunks.mode == ChunkMode::kAuto && options.orientation.axis == AxisSource::kSkeleton;
  return uses_chunks(options.chunks, face_count) && !whole_only;
}

ChunkedEdits::ChunkedEdits() = default;
ChunkedEdits::~ChunkedEdits() = default;
ChunkedEdits::ChunkedEdits(ChunkedEdits&&) noexcept = default;
ChunkedEdits& ChunkedEdits::operator=(ChunkedEdits&&) noexcept = default;

Status ChunkedEdits::prepare(const Mesh& mesh, const MapTextureOptions& options) {
  auto layout = std::make_shared<Layout>();
  TAILOR_RETURN_IF_ERROR(plan_chunks(mesh, options.chunks, layout->plan, options.mapping.threads));
  layout->texels_per_unit = chunk_texels_per_unit(mesh, options);
  const ChunkPlan& plan = layout->plan;
  const size_t chunks = plan.chunk_count();
  layout->chunk_of.resize(mesh.face_count());
  for (uint32_t c = 0; c < chunks; ++c)
    for (const uint32_t f : chunk_faces(plan, c)) layout->chunk_of[f] = c;
  layout_ = std::move(layout);
  position_.assign(mesh.face_count(), 0);
  first_.assign(chunks + 1, 0);
  patches_.assign(chunks, 0);
  dirty_.assign(chunks, 0);
  kept_.clear();
  return Status::ok();
}

Status ChunkedEdits::map_all(const Mesh& mesh, const Topology& topology, const MapTextureOptions& options,
                             Atlas& atlas) {
  TAILOR_RETURN_IF_ERROR(prepare(mesh, options));
  MapTextureOptions o = options;
  o.measure = false;
  TextureMap map;
  TAILOR_RETURN_IF_ERROR(map_texture(mesh, topology, o, map));
  atlas = std::move(map.atlas);
  // map_texture numbers each chunk's patches after those of the chunks before it (cell order).
  const ChunkPlan& plan = layout_->plan;
  for (uint32_t c = 0; c < plan.chunk_count(); ++c) {
    uint32_t last = 0;
    for (const uint32_t f : chunk_faces(plan, c)) last = std::max(last, atlas.patch[f]);
    patches_[c] = last + 1 - first_[c];
    first_[c + 1] = last + 1;
  }
  return Status::ok();
}

std::vector<uint32_t> ChunkedEdits::touched(const Mesh& mesh, std::span<const uint32_t> flipped,
                                            std::span<const OrientationStroke> changed_strokes) const {
  const Layout& layout = *layout_;
  const ChunkPlan& plan = layout.plan;
  std::vector<uint8_t> hit(plan.chunk_count(), 0);
  for (const uint32_t f : flipped) hit[layout.chunk_of[f]] = 1;
  if (!changed_strokes.empty()) {
    std::vector<OrientationStroke> grown(changed_strokes.begin(), changed_strokes.end());
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (OrientationStroke& s : grown) {
      s.radius = static_cast<float>(double{s.radius} * (1 + kReachMargin));
      for (size_t i = 0; i + 2 < s.points.size(); i += 3)
        for (size_t k = 0; k < 3; ++k) {
          lo[k] = std::min(lo[k], double{s.points[i + k]} - s.radius);
          hi[k] = std::max(hi[k], double{s.points[i + k]} + s.radius);
        }
    }
    const StrokeField field(grown);
    const float* pos = mesh.positions.data();
    const uint32_t* idx = mesh.indices.data();
    for (uint32_t c = 0; c < plan.chunk_count(); ++c) {
      if (hit[c]) continue;
      // Chunks whose box misses the strokes' box (grown by their radii) hold no face they reach.
      bool apart = false;
      const double size = plan.chunk_size(c);
      const std::array<double, 3> origin = plan.chunk_origin(c);
      for (size_t k = 0; k < 3; ++k) apart = apart || origin[k] > hi[k] || origin[k] + size < lo[k];
      if (apart) continue;
      for (const uint32_t f : chunk_faces(plan, c)) {
        double q[3] = {0, 0, 0};
        for (int k = 0; k < 3; ++k)
          for (int j = 0; j < 3; ++j) q[j] += pos[3 * size_t{idx[3 * size_t{f} + k]} + j];
        for (double& x : q) x /= 3;
        double direction[3];
        if (field.sample(q, direction) > 0) {
          hit[c] = 1;
          break;
        }
      }
    }
  }
  std::vector<uint32_t> out;
  for (uint32_t c = 0; c < plan.chunk_count(); ++c)
    if (hit[c]) out.push_back(c);
  return out;
}

void ChunkedEdits::load_atlas(Kept& k, const Atlas& atlas) const {
  const size_t n = k.w.faces.size();
  Atlas& a = k.w.map.atlas;
  a.corner_uv.resize(6 * n);
  a.patch.resize(n);
  a.patch_count = patches_[k.chunk];
  const uint32_t first = first_[k.chunk];
  for (size_t i = 0; i < n; ++i) {
    const ChunkFace& face = k.w.faces[i];
    for (uint32_t j = 0; j < 3; ++j) {
      const size_t corner = 3 * size_t{face.face} + (face.rotation + j) % 3;
      a.corner_uv[6 * i + 2 * j] = atlas.corner_uv[2 * corner];
      a.corner_uv[6 * i + 2 * j + 1] = atlas.corner_uv[2 * corner + 1];
    }
    a.patch[i] = atlas.patch[face.face] - first;
  }
}

void ChunkedEdits::trim() {
  // The forms an update uses stay until it ends: the least recently used go after it.
  while (kept_.size() > kKeptChunks)
    kept_.erase(
        std::min_element(kept_.begin(), kept_.end(), [](const auto& a, const auto& b) { return a->used < b->used; }));
}

void ChunkedEdits::drop(uint32_t chunk) {
  kept_.erase(std::remove_if(kept_.begin(), kept_.end(), [&](const auto& k) { return k->chunk == chunk; }),
              kept_.end());
}

ChunkedEdits::Kept* ChunkedEdits::find_or_add(uint32_t chunk) {
  ++clock_;
  for (const auto& k : kept_)
    if (k->chunk == chunk) {
      k->used = clock_;
      return k.get();
    }
  auto k = std::make_unique<Kept>();
  k->chunk = chunk;
  k->used = clock_;
  kept_.push_back(std::move(k));
  return kept_.back().get();
}

Status ChunkedEdits::build(const Mesh& mesh, const MapTextureOptions& options, const Atlas& atlas, Kept* k) {
  const uint32_t chunk = k->chunk;
  const Layout& layout = *layout_;
  const ChunkPlan& plan = layout.plan;
  build_chunk_mesh(mesh, chunk_faces(plan, chunk), plan.chunk_origin(chunk), plan.chunk_size(chunk),
                   options.mapping.seam_faces, k->w);
  for (size_t i = 0; i < k->w.faces.size(); ++i) position_[k->w.faces[i].face] = static_cast<uint32_t>(i);
  k->topology = build_topology(k->w.mesh);
  const MapTextureOptions o = chunk_options(layout, options, chunk, k->w.seam_flags);
  TAILOR_RETURN_IF_ERROR(
      compute_orientation_setup(k->w.mesh, k->topology, o.orientation, k->w.map.frames, &k->local.setup));
  load_atlas(*k, atlas);
  k->local.seeds = component_seed_faces(k->w.mesh, k->topology, k->w.map.frames, o.mapping);
  k->local.region.assign(k->w.faces.size(), 0);
  k->local.ring.resize(k->w.faces.size());
  k->local.ready = true;
  return Status::ok();
}

void ChunkedEdits::renumber(Atlas& atlas, std::span<const uint32_t> touched, uint32_t& changed) {
  const ChunkPlan& plan = layout_->plan;
  const size_t chunks = plan.chunk_count();
  std::vector<uint32_t> first(chunks + 1, 0);
  for (size_t c = 0; c < chunks; ++c) first[c + 1] = first[c] + patches_[c];
  size_t t = 0;
  for (uint32_t c = 0; c < chunks; ++c) {
    while (t < touched.size() && touched[t] < c) ++t;
    if ((t < touched.size() && touched[t] == c) || first[c] == first_[c]) continue;
    // A chunk before this one changed its patch count: the same patches, other ids.
    const uint32_t shift = first[c] - first_[c];
    const std::span<const uint32_t> faces = chunk_faces(plan, c);
    for (const uint32_t f : faces) atlas.patch[f] += shift;
    changed += static_cast<uint32_t>(faces.size());
  }
  first_ = std::move(first);
  atlas.patch_count = first_[chunks];
}

void ChunkedEdits::write_chunk(uint32_t chunk, const Atlas& chunk_atlas, const std::vector<ChunkFace>& faces,
                               Atlas& atlas, uint32_t& changed) const {
  const uint32_t first = first_[chunk];
  for (size_t i = 0; i < faces.size(); ++i) {
    const ChunkFace& face = faces[i];
    bool same = atlas.patch[face.face] == first + chunk_atlas.patch[i];
    atlas.patch[face.face] = first + chunk_atlas.patch[i];
    for (uint32_t j = 0; j < 3; ++j) {
      const size_t corner = 3 * size_t{face.face} + (face.rotation + j) % 3;
      float* uv = &atlas.corner_uv[2 * corner];
      same = same && std::bit_cast<uint32_t>(uv[0]) == std::bit_cast<uint32_t>(chunk_atlas.corner_uv[6 * i + 2 * j]) &&
             std::bit_cast<uint32_t>(uv[1]) == std::bit_cast<uint32_t>(chunk_atlas.corner_uv[6 * i + 2 * j + 1]);
      uv[0] = chunk_atlas.corner_uv[6 * i + 2 * j];
      uv[1] = chunk_atlas.corner_uv[6 * i + 2 * j + 1];
    }
    changed += same ? 0u : 1u;
  }
}

Status ChunkedEdits::map_chunk_fresh(const Layout& layout, const Mesh& mesh, const MapTextureOptions& options,
                                     uint32_t chunk, uint32_t threads, ProgressCallback progress, ChunkWorker& w) {
  const ChunkPlan& plan = layout.plan;
  build_chunk_mesh(mesh, chunk_faces(plan, chunk), plan.chunk_origin(chunk), plan.chunk_size(chunk),
                   options.mapping.seam_faces, w);
  return map_chunk(options, plan.chunk_origin(chunk), plan.chunk_size(chunk), layout.texels_per_unit, threads,
                   std::move(progress), w);
}

void ChunkedEdits::adopt(const MapTextureOptions& options, std::span<const uint32_t> chunks,
                         std::span<ChunkWorker> maps, Atlas& atlas, uint32_t& changed) {
  for (size_t i = 0; i < chunks.size(); ++i) {
    const uint32_t c = chunks[i];
    patches_[c] = maps[i].map.atlas.patch_count;
    dirty_[c] = 0;
  }
  renumber(atlas, chunks, changed);
  for (size_t i = 0; i < chunks.size(); ++i) {
    const uint32_t c = chunks[i];
    write_chunk(c, maps[i].map.atlas, maps[i].faces, atlas, changed);
    // A kept canonical form takes the chunk's map (the same faces in the same order; its frames
    // are those the map computed, as the seeds of its next local update).
    for (const auto& k : kept_)
      if (k->chunk == c) {
        k->w.map.atlas = maps[i].map.atlas;
        const MapTextureOptions o = chunk_options(*layout_, options, c, k->w.seam_flags);
        k->local.seeds = component_seed_faces(k->w.mesh, k->topology, k->w.map.frames, o.mapping);
      }
  }
}

Status ChunkedEdits::update(const Mesh& mesh, const MapTextureOptions& options, std::span<const uint32_t> flipped,
                            std::span<const OrientationStroke> changed_strokes, Atlas& atlas, uint32_t& changed) {
  changed = 0;
  const std::vector<uint32_t> chunks = touched(mesh, flipped, changed_strokes);
  if (chunks.empty()) return Status::ok();
  const Layout& layout = *layout_;
  const MappingOptions& m = options.mapping;
  const bool local = m.mode == MappingMode::kPatches && m.symmetry == 1 && options.orientation.smooth_passes == 0;
  if (!local) {
    // The touched chunks mapped again (their smoothing, grid or thesis growth spans the chunk).
    std::vector<ChunkWorker> maps(chunks.size());
    std::vector<Status> statuses(chunks.size(), Status::ok());
    for_each_index(chunks.size(), m.threads, [&](size_t i) {
      statuses[i] = map_chunk_fresh(layout, mesh, options, chunks[i], m.threads, {}, maps[i]);
    });
    for (const Status& s : statuses) TAILOR_RETURN_IF_ERROR(s);
    for (const uint32_t c : chunks) drop(c);
    adopt(options, chunks, maps, atlas, changed);
    return Status::ok();
  }
  // The canonical forms (found or added here, built below), then each touched chunk's update on
  // its own thread: each writes only its own form, its patch count and its faces' positions.
  std::vector<Kept*> forms(chunks.size(), nullptr);
  std::vector<uint8_t> fresh(chunks.size(), 0);
  for (size_t i = 0; i < chunks.size(); ++i) {
    const size_t before = kept_.size();
    forms[i] = find_or_add(chunks[i]);
    fresh[i] = kept_.size() > before;
  }
  std::vector<Status> statuses(chunks.size(), Status::ok());
  for_each_index(chunks.size(), m.threads, [&](size_t i) {
    const uint32_t c = chunks[i];
    Kept& k = *forms[i];
    if (fresh[i]) {
      statuses[i] = build(mesh, options, atlas, &k);
      if (!statuses[i]) return;
    }
    // The chunk's flipped faces (canonical ids, in the order given) and its new seam flags.
    std::vector<uint32_t> flipped_here;
    for (const uint32_t f : flipped)
      if (layout.chunk_of[f] == c) {
        const uint32_t p = position_[f];
        k.w.seam_flags[p] = options.mapping.seam_faces[f];
        flipped_here.push_back(p);
      }
    const MapTextureOptions o = chunk_options(layout, options, c, k.w.seam_flags);
    std::vector<uint32_t> affected;
    refresh_stroke_frames(k.w.mesh, k.topology, o, changed_strokes, k.w.map, k.local, affected);
    uint32_t region_changed = 0;
    statuses[i] = update_region(k.w.mesh, k.topology, o, flipped_here, affected, k.w.map, k.local, region_changed);
    patches_[c] = k.w.map.atlas.patch_count;
  });
  Status status = Status::ok();
  for (const Status& s : statuses)
    if (status.is_ok() && !s) status = s;
  if (!status) {
    // A kept form may be half updated: the next edit builds it again from the atlas.
    for (const uint32_t c : chunks) drop(c);
    trim();
    return status;
  }
  for (const uint32_t c : chunks) dirty_[c] = 1;
  renumber(atlas, chunks, changed);
  for (size_t i = 0; i < chunks.size(); ++i)
    write_chunk(chunks[i], forms[i]->w.map.atlas, forms[i]->w.faces, atlas, changed);
  trim();
  return Status::ok();
}

void ChunkedEdits::restore(const MapTextureOptions& options, std::span<const uint32_t> flipped,
                           std::span<const OrientationStroke> changed_strokes, const Atlas& atlas,
                           std::vector<uint8_t> dirty, std::vector<uint32_t> patches) {
  const Layout& layout = *layout_;
  dirty_ = std::move(dirty);
  patches_ = std::move(patches);
  for (size_t c = 0; c < patches_.size(); ++c) first_[c + 1] = first_[c] + patches_[c];
  for (const auto& k : kept_) {
    for (const uint32_t f : flipped)
      if (layout.chunk_of[f] == k->chunk) k->w.seam_flags[position_[f]] = options.mapping.seam_faces[f];
    const MapTextureOptions o = chunk_options(layout, options, k->chunk, k->w.seam_flags);
    std::vector<uint32_t> affected;
    refresh_stroke_frames(k->w.mesh, k->topology, o, changed_strokes, k->w.map, k->local, affected);
    load_atlas(*k, atlas);
  }
}

std::vector<uint32_t> ChunkedEdits::dirty_chunks() const {
  std::vector<uint32_t> out;
  for (uint32_t c = 0; c < dirty_.size(); ++c)
    if (dirty_[c]) out.push_back(c);
  return out;
}

bool ChunkedEdits::any_dirty() const { return std::find(dirty_.begin(), dirty_.end(), 1) != dirty_.end(); }

}  // namespace tailor::internal
