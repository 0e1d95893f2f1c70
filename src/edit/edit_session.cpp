// EditSession (tailor/edit_session.h): the state a user edits, its history and its versions.
//
// Locks: edit_mutex serialises the edits (apply, undo, redo) and the publication of a settle;
// versions_mutex guards the kept UVs of recent versions (corner_uv_repeats). settle() computes
// its map with neither held, on a copy of the state, and gives up when an edit arrives (the
// `edits` counter, read by its progress callback), so an edit never waits for a settle.
#include "tailor/edit_session.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <deque>
#include <mutex>
#include <span>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

#include "edit/chunk_edit.h"
#include "edit/local_update.h"
#include "surface/stroke_field.h"

namespace tailor {
namespace {

// The stroke points a session holds at most: every edit's field samples all of them, so a session
// fed without end would grow in memory and in time per edit (nine requests of 100k strokes: 540 MB,
// 3.1 s an edit). A painted stroke has tens of points; tens of thousands of strokes fit.
constexpr size_t kMaxSessionStrokePoints = size_t{1} << 20;
// Versions whose UVs corner_uv_repeats still answers, and history states whose atlas is kept so
// that undo and redo restore them bit for bit (older ones are mapped again).
constexpr size_t kKeptVersions = 8;
constexpr size_t kKeptAtlases = 8;
// From this many UV floats on (2 per corner: 100k faces) publish copies on two threads.
constexpr size_t kParallelPublishCorners = 600000;

// The stroke points of these lists together, refused beyond kMaxSessionStrokePoints.
Status check_session_stroke_points(std::span<const OrientationStroke> held, std::span<const OrientationStroke> added) {
  size_t points = 0;
  for (const auto list : {held, added})
    for (const OrientationStroke& s : list) points += s.points.size() / 3;
  if (points <= kMaxSessionStrokePoints) return Status::ok();
  return Status::error(ErrorCode::kInvalidArgument, "",
                       "a session holds at most " + std::to_string(kMaxSessionStrokePoints) +
                           " stroke points, these are " + std::to_string(points) +
                           ": map them with tailor map --strokes instead");
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

// The types EditSession::State holds: named (not in an unnamed namespace) because State is.
namespace edit_types {

// One applied edit, as what it changed: enough to undo and redo it.
struct Step {
  std::vector<uint32_t> flipped;           // faces whose seam flag flipped (ascending)
  std::vector<OrientationStroke> strokes;  // strokes appended
  std::optional<MapTextureOptions> options_before, options_after;
};

// The atlas a history state had when it was last current (settled or not).
struct KeptAtlas {
  size_t position = 0;  // steps in effect
  Atlas atlas;
  bool settled = false;
  std::vector<uint8_t> dirty;     // chunked sessions: the chunks whose UVs were a local update
  std::vector<uint32_t> patches;  // chunked sessions: each chunk's patch count
};

}  // namespace edit_types
using edit_types::KeptAtlas;
using edit_types::Step;

namespace {

// The session's options with the parts it owns cleared: spans (its own seam flags and strokes are
// set when mapping) and the progress callback.
MapTextureOptions own_options(const MapTextureOptions& options) {
  MapTextureOptions o = options;
  o.mapping.seam_faces = {};
  o.mapping.progress = nullptr;
  o.orientation.strokes = {};
  return o;
}

// Faces whose UVs or patch differ between two atlases of the same mesh.
uint32_t count_changed(const Atlas& a, const Atlas& b) {
  if (a.patch.size() != b.patch.size() || a.corner_uv.size() != b.corner_uv.size())
    return static_cast<uint32_t>(std::max(a.patch.size(), b.patch.size()));
  uint32_t changed = 0;
  for (size_t f = 0; f < a.patch.size(); ++f)
    changed += internal::same_face_bits(a.patch[f], &a.corner_uv[6 * f], b.patch[f], &b.corner_uv[6 * f]) ? 0u : 1u;
  return changed;
}

}  // namespace

struct EditSession::State {
  Mesh mesh;
  Topology topology;

  std::mutex edit_mutex;                   // everything below down to `kept`, and the publication of a settle
  std::vector<uint8_t> seam;               // #F user seam flags
  std::vector<OrientationStroke> strokes;  // in the order added
  MapTextureOptions options;               // own_options()
  std::vector<Step> steps;                 // the history
  size_t applied = 0;                      // steps[0, applied) are in effect
  TextureMap map;                          // the current version's atlas, and its frames unless chunked
  internal::LocalUpdate local;             // what the fast update keeps between edits (whole mesh)
  bool chunked = false;                    // the options cut the mesh into chunks: edits go chunk by chunk
  internal::ChunkedEdits chunks;           // chunked: the plan, the chunks' patch ranges and dirty flags
  std::deque<KeptAtlas> kept;              // recent history states' atlases
  KeptAtlas spare;                         // one dropped from `kept`, its arrays kept for reuse

  std::atomic<uint64_t> version{0};
  std::atomic<bool> settled{true};
  std::atomic<uint64_t> edits{0};  // edits begun: a settle in flight gives up when it changes

  mutable std::mutex versions_mutex;
  std::deque<std::pair<uint64_t, std::vector<float>>> versions;  // recent versions' UVs in repeats

  // The options of a state with its seam flags and strokes set.
  static MapTextureOptions with_state(const MapTextureOptions& base, const std::vector<uint8_t>& seam_flags,
                                      const std::vector<OrientationStroke>& stroke_list) {
    MapTextureOptions o = base;
    o.mapping.seam_faces = seam_flags;
    o.orientation.strokes = stroke_list;
    return o;
  }

  // The settle of a chunked session: the dirty chunks mapped again by the whole pipeline (without
  // a lock, on a snapshot of the state; an edit arriving meanwhile cancels it), then put in.
  Status settle_chunks(const internal::ChunkedEdits::Layout& layout, const std::vector<uint8_t>& seam_flags,
                       const std::vector<OrientationStroke>& stroke_list, const MapTextureOptions& base,
                       const std::vector<uint32_t>& dirty, uint64_t edits_seen,
                       std::chrono::steady_clock::time_point start, EditResult& result) {
    const MapTextureOptions o = with_state(base, seam_flags, stroke_list);
    const auto still = [this, edits_seen](float) { return edits.load() == edits_seen; };
    std::vector<internal::ChunkWorker> maps(dirty.size());
    for (size_t i = 0; i < dirty.size(); ++i) {
      const Status s =
          internal::ChunkedEdits::map_chunk_fresh(layout, mesh, o, dirty[i], o.mapping.threads, still, maps[i]);
      if (s.code() == ErrorCode::kCancelled || edits.load() != edits_seen) {
        result.ms = ms_since(start);
        return Status::ok();
      }
      TAILOR_RETURN_IF_ERROR(s);
    }
    const std::lock_guard<std::mutex> lock(edit_mutex);
    result.ms = ms_since(start);
    if (edits.load() != edits_seen) {
      result.version = version.load();
      return Status::ok();
    }
    chunks.adopt(o, dirty, maps, map.atlas, result.changed_faces);
    if (result.changed_faces == 0) {
      settled.store(true);
      keep_atlas(true);
    } else {
      publish(version.load() + 1, true);
    }
    result.version = version.load();
    result.settled = true;
    result.ms = ms_since(start);
    return Status::ok();
  }

  // Makes the current atlas version v's and keeps its UVs.
  void publish(uint64_t v, bool is_settled) {
    const double su = 1.0 / options.metrics.texture_width_px, sv = 1.0 / options.metrics.texture_height_px;
    const std::vector<float>& px = map.atlas.corner_uv;
    // The oldest kept version's array, when it is about to go, is reused: 24 bytes per face of
    // fresh memory at every edit cost more in page faults than the conversion itself.
    std::vector<float> repeats;
    {
      const std::lock_guard<std::mutex> lock(versions_mutex);
      if (versions.size() >= kKeptVersions) {
        repeats = std::move(versions.front().second);
        versions.pop_front();
      }
    }
    // On a large mesh the atlas kept for undo is copied on a second thread meanwhile: both are
    // passes over tens of megabytes, most of an edit's time once the chunks are mapped.
    std::thread keeper;
    if (px.size() >= kParallelPublishCorners) {
      try {
        keeper = std::thread([this, is_settled] { keep_atlas(is_settled); });
      } catch (const std::system_error&) {  // no thread to be had: copied below
      }
    }
    repeats.resize(px.size());
    for (size_t i = 0; i + 1 < px.size(); i += 2) {
      repeats[i] = static_cast<float>(px[i] * su);
      repeats[i + 1] = static_cast<float>(px[i + 1] * sv);
    }
    if (keeper.joinable())
      keeper.join();
    else
      keep_atlas(is_settled);
    {
      const std::lock_guard<std::mutex> lock(versions_mutex);
      versions.emplace_back(v, std::move(repeats));
      while (versions.size() > kKeptVersions) versions.pop_front();
    }
    settled.store(is_settled);
    version.store(v);
  }

  // Remembers the current atlas for history position `applied` (replacing an older one).
  void keep_atlas(bool is_settled) {
    // The entry replaced, or the oldest when it is about to go, gives its arrays to the new one
    // (assigning into them costs no page faults).
    KeptAtlas entry;
    for (auto it = kept.begin(); it != kept.end(); ++it)
      if (it->position == applied) {
        entry = std::move(*it);
        kept.erase(it);
        break;
      }
    if (entry.atlas.corner_uv.empty() && kept.size() >= kKeptAtlases) {
      entry = std::move(kept.front());
      kept.pop_front();
    } else if (entry.atlas.corner_uv.empty()) {
      entry = std::move(spare);
      spare = KeptAtlas{};
    }
    entry.position = applied;
    entry.atlas.corner_uv.assign(map.atlas.corner_uv.begin(), map.atlas.corner_uv.end());
    entry.atlas.patch.assign(map.atlas.patch.begin(), map.atlas.patch.end());
    entry.atlas.patch_count = map.atlas.patch_count;
    entry.settled = is_settled;
    entry.dirty = chunked ? chunks.dirty_flags() : std::vector<uint8_t>{};
    entry.patches = chunked ? chunks.patch_counts() : std::vector<uint32_t>{};
    kept.push_back(std::move(entry));
    while (kept.size() > kKeptAtlases) kept.pop_front();
  }

  // The state moved to history position `applied` by undo or redo: its kept atlas when there is
  // one (bit for bit what it showed, the frames updated to match), else an update as for an edit.
  Status move_to_position(const std::vector<uint32_t>& flipped, const std::vector<OrientationStroke>& changed_strokes,
                          bool options_changed, EditResult& result) {
    const KeptAtlas* found = nullptr;
    for (const KeptAtlas& k : kept)
      if (k.position == applied) found = &k;
    if (!found) {
      TAILOR_RETURN_IF_ERROR(update(flipped, changed_strokes, options_changed, result.changed_faces));
      publish(version.load() + 1, chunked && !chunks.any_dirty());
      return Status::ok();
    }
    const MapTextureOptions o = with_state(options, seam, strokes);
    // A history state's options decide its chunks: the kept atlas was cut as they cut it now.
    if (internal::session_uses_chunks(o, mesh.face_count())) {
      if (options_changed || !chunked) {
        TAILOR_RETURN_IF_ERROR(chunks.prepare(mesh, o));
        chunked = true;
        map.frames = FaceFrames{};
        local.reset();
      }
      result.changed_faces = count_changed(map.atlas, found->atlas);
      map.atlas = found->atlas;
      chunks.restore(o, flipped, changed_strokes, map.atlas, found->dirty, found->patches);
      publish(version.load() + 1, found->settled);
      return Status::ok();
    }
    chunked = false;
    if (options_changed || !internal::can_update_locally(o, local)) {
      local.reset();
      TAILOR_RETURN_IF_ERROR(
          internal::compute_orientation_setup(mesh, topology, o.orientation, map.frames, &local.setup));
      local.seeds = component_seed_faces(mesh, topology, map.frames, o.mapping);
      local.region.assign(mesh.face_count(), 0);
      local.ring.resize(mesh.face_count());
      local.ready = true;
    } else {
      std::vector<uint32_t> affected;
      internal::refresh_stroke_frames(mesh, topology, o, changed_strokes, map, local, affected);
    }
    result.changed_faces = count_changed(map.atlas, found->atlas);
    map.atlas = found->atlas;
    publish(version.load() + 1, found->settled);
    return Status::ok();
  }

  // The new state's map after an edit: a local update of the current one where possible, else the
  // full map. changed: faces whose UVs or patch changed.
  Status update(const std::vector<uint32_t>& flipped, const std::vector<OrientationStroke>& changed_strokes,
                bool options_changed, uint32_t& changed) {
    const MapTextureOptions o = with_state(options, seam, strokes);
    if (options_changed && internal::session_uses_chunks(o, mesh.face_count())) {
      internal::ChunkedEdits fresh;
      Atlas next;
      TAILOR_RETURN_IF_ERROR(fresh.map_all(mesh, topology, o, next));
      changed = count_changed(map.atlas, next);
      map.atlas = std::move(next);
      map.frames = FaceFrames{};
      chunks = std::move(fresh);
      chunked = true;
      local.reset();
      return Status::ok();
    }
    if (chunked && !options_changed) return chunks.update(mesh, o, flipped, changed_strokes, map.atlas, changed);
    if (options_changed || !internal::can_update_locally(o, local)) {
      chunked = false;
      TextureMap next;
      TAILOR_RETURN_IF_ERROR(internal::map_keeping_setup(mesh, topology, o, next, local));
      changed = count_changed(map.atlas, next.atlas);
      map = std::move(next);
      return Status::ok();
    }
    std::vector<uint32_t> affected;
    internal::refresh_stroke_frames(mesh, topology, o, changed_strokes, map, local, affected);
    return internal::update_region(mesh, topology, o, flipped, affected, map, local, changed);
  }
};

EditSession::EditSession() : state_(std::make_unique<State>()) {}
EditSession::~EditSession() = default;

Status EditSession::open(Mesh mesh, const MapTextureOptions& options, std::unique_ptr<EditSession>& session) {
  session.reset();
  std::unique_ptr<EditSession> s(new EditSession());
  State& st = *s->state_;
  st.mesh = std::move(mesh);
  st.topology = build_topology(st.mesh);
  TAILOR_RETURN_IF_ERROR(check_map_options(options));
  st.options = own_options(options);
  if (!options.mapping.seam_faces.empty() && options.mapping.seam_faces.size() != st.mesh.face_count())
    return Status::error(ErrorCode::kInvalidArgument, "", "seam face flags must hold one entry per face");
  if (options.mapping.seam_faces.empty())
    st.seam.assign(st.mesh.face_count(), 0);
  else
    st.seam.assign(options.mapping.seam_faces.begin(), options.mapping.seam_faces.end());
  TAILOR_RETURN_IF_ERROR(internal::check_strokes(options.orientation.strokes));
  TAILOR_RETURN_IF_ERROR(check_session_stroke_points(options.orientation.strokes, {}));
  st.strokes.assign(options.orientation.strokes.begin(), options.orientation.strokes.end());
  MapTextureOptions first = State::with_state(st.options, st.seam, st.strokes);
  first.mapping.progress = options.mapping.progress;
  st.chunked = internal::session_uses_chunks(first, st.mesh.face_count());
  if (st.chunked)
    TAILOR_RETURN_IF_ERROR(st.chunks.map_all(st.mesh, st.topology, first, st.map.atlas));
  else
    TAILOR_RETURN_IF_ERROR(internal::map_keeping_setup(st.mesh, st.topology, first, st.map, st.local));
  st.publish(0, true);
  session = std::move(s);
  return Status::ok();
}

Status EditSession::apply(const EditRequest& edit, EditResult& result) {
  const auto start = std::chrono::steady_clock::now();
  State& st = *state_;
  st.edits.fetch_add(1);
  const std::lock_guard<std::mutex> lock(st.edit_mutex);
  result = EditResult{};
  // === Checks: nothing changes unless the whole edit is valid ===
  const size_t face_count = st.mesh.face_count();
  for (const std::vector<uint32_t>* list : {&edit.remove_seam_faces, &edit.add_seam_faces})
    for (const uint32_t f : *list)
      if (f >= face_count)
        return Status::error(
            ErrorCode::kInvalidArgument, "",
            "face " + std::to_string(f) + " out of range (mesh has " + std::to_string(face_count) + " faces)");
  TAILOR_RETURN_IF_ERROR(internal::check_strokes(edit.strokes));
  if (!edit.strokes.empty()) TAILOR_RETURN_IF_ERROR(check_session_stroke_points(st.strokes, edit.strokes));
  std::optional<MapTextureOptions> new_options;
  if (edit.options) {
    TAILOR_RETURN_IF_ERROR(check_map_options(*edit.options));
    new_options = own_options(*edit.options);
  }

  // === The step: options, removed then added seam faces, strokes ===
  Step step;
  std::vector<uint8_t> seam = st.seam;  // the flags after the edit (a copy: the edit may still fail)
  for (const uint32_t f : edit.remove_seam_faces) seam[f] = 0;
  for (const uint32_t f : edit.add_seam_faces) seam[f] = 1;
  auto note_flip = [&](uint32_t f) {
    if (seam[f] != st.seam[f]) step.flipped.push_back(f);
  };
  for (const uint32_t f : edit.remove_seam_faces) note_flip(f);
  for (const uint32_t f : edit.add_seam_faces) note_flip(f);
  std::sort(step.flipped.begin(), step.flipped.end());
  step.flipped.erase(std::unique(step.flipped.begin(), step.flipped.end()), step.flipped.end());
  step.strokes = edit.strokes;
  // New options count as a change (MapTextureOptions has no operator==; the page sends them only
  // when a control changes): the whole mesh is mapped again.
  const bool differs = new_options.has_value();
  if (new_options) {
    step.options_before = st.options;
    step.options_after = new_options;
  }
  if (step.flipped.empty() && step.strokes.empty() && !differs) {
    result.version = st.version.load();
    result.settled = st.settled.load();
    result.ms = ms_since(start);
    return Status::ok();
  }

  // === Update: on failure (options map_texture refuses) the state is put back ===
  const std::vector<uint8_t> seam_before = std::move(st.seam);
  const size_t strokes_before = st.strokes.size();
  const MapTextureOptions options_before = st.options;
  st.seam = std::move(seam);
  st.strokes.insert(st.strokes.end(), step.strokes.begin(), step.strokes.end());
  if (new_options) st.options = *new_options;
  if (Status s = st.update(step.flipped, step.strokes, differs, result.changed_faces); !s) {
    // Only the full map can fail (options map_texture refuses): the frames and atlas are intact.
    st.seam = seam_before;
    st.strokes.resize(strokes_before);
    st.options = options_before;
    return s;
  }
  // A new step: the redo branch is dropped with the atlases kept for it.
  st.steps.resize(st.applied);
  for (auto it = st.kept.begin(); it != st.kept.end();)
    if (it->position > st.applied) {
      st.spare = std::move(*it);  // its arrays serve the next keep_atlas
      it = st.kept.erase(it);
    } else {
      ++it;
    }
  st.steps.push_back(std::move(step));
  st.applied = st.steps.size();
  st.publish(st.version.load() + 1, st.chunked && !st.chunks.any_dirty());
  result.version = st.version.load();
  result.settled = st.settled.load();
  result.ms = ms_since(start);
  return Status::ok();
}

Status EditSession::undo(EditResult& result) {
  const auto start = std::chrono::steady_clock::now();
  State& st = *state_;
  st.edits.fetch_add(1);
  const std::lock_guard<std::mutex> lock(st.edit_mutex);
  result = EditResult{};
  if (st.applied == 0) return Status::error(ErrorCode::kInvalidArgument, "", "nothing to undo");
  const Step& step = st.steps[st.applied - 1];
  for (const uint32_t f : step.flipped) st.seam[f] ^= 1;
  st.strokes.resize(st.strokes.size() - step.strokes.size());
  if (step.options_before) st.options = *step.options_before;
  --st.applied;
  TAILOR_RETURN_IF_ERROR(st.move_to_position(step.flipped, step.strokes, step.options_before.has_value(), result));
  result.version = st.version.load();
  result.settled = st.settled.load();
  result.ms = ms_since(start);
  return Status::ok();
}

Status EditSession::redo(EditResult& result) {
  const auto start = std::chrono::steady_clock::now();
  State& st = *state_;
  st.edits.fetch_add(1);
  const std::lock_guard<std::mutex> lock(st.edit_mutex);
  result = EditResult{};
  if (st.applied == st.steps.size()) return Status::error(ErrorCode::kInvalidArgument, "", "nothing to redo");
  const Step& step = st.steps[st.applied];
  for (const uint32_t f : step.flipped) st.seam[f] ^= 1;
  st.strokes.insert(st.strokes.end(), step.strokes.begin(), step.strokes.end());
  if (step.options_after) st.options = *step.options_after;
  ++st.applied;
  TAILOR_RETURN_IF_ERROR(st.move_to_position(step.flipped, step.strokes, step.options_after.has_value(), result));
  result.version = st.version.load();
  result.settled = st.settled.load();
  result.ms = ms_since(start);
  return Status::ok();
}

Status EditSession::settle(EditResult& result) {
  const auto start = std::chrono::steady_clock::now();
  State& st = *state_;
  result = EditResult{};
  std::vector<uint8_t> seam;
  std::vector<OrientationStroke> strokes;
  MapTextureOptions options;
  uint64_t edits = 0;
  bool chunked = false;
  std::shared_ptr<const internal::ChunkedEdits::Layout> layout;
  std::vector<uint32_t> dirty;
  {
    const std::lock_guard<std::mutex> lock(st.edit_mutex);
    result.version = st.version.load();
    if (st.settled.load()) {
      result.settled = true;
      result.ms = ms_since(start);
      return Status::ok();
    }
    seam = st.seam;
    strokes = st.strokes;
    options = st.options;
    edits = st.edits.load();
    chunked = st.chunked;
    if (chunked) {
      layout = st.chunks.layout();
      dirty = st.chunks.dirty_chunks();
    }
  }
  if (chunked) return st.settle_chunks(*layout, seam, strokes, options, dirty, edits, start, result);
  // The full map without a lock; an edit arriving meanwhile cancels it.
  TextureMap map;
  internal::LocalUpdate local;
  MapTextureOptions o = State::with_state(options, seam, strokes);
  o.mapping.progress = [&st, edits](float) { return st.edits.load() == edits; };
  // Every stage's progress too (orientation, relaxation, metrics): the relaxation alone takes as long
  // as the growth on large meshes, and an edit should not wait for it to share the cores.
  o.stage_progress = [&st, edits](std::string_view, float) { return st.edits.load() == edits; };
  const Status s = internal::map_keeping_setup(st.mesh, st.topology, o, map, local);
  result.ms = ms_since(start);
  if (s.code() == ErrorCode::kCancelled) return Status::ok();
  TAILOR_RETURN_IF_ERROR(s);
  const std::lock_guard<std::mutex> lock(st.edit_mutex);
  if (st.edits.load() != edits) {
    result.version = st.version.load();
    return Status::ok();
  }
  result.changed_faces = count_changed(st.map.atlas, map.atlas);
  st.map = std::move(map);
  st.local = std::move(local);
  if (result.changed_faces == 0) {
    st.settled.store(true);
    st.keep_atlas(true);
  } else {
    st.publish(st.version.load() + 1, true);
  }
  result.version = st.version.load();
  result.settled = true;
  result.ms = ms_since(start);
  return Status::ok();
}

uint64_t EditSession::version() const { return state_->version.load(); }
bool EditSession::settled() const { return state_->settled.load(); }

bool EditSession::corner_uv_repeats(uint64_t version, std::vector<float>& out) const {
  const std::lock_guard<std::mutex> lock(state_->versions_mutex);
  for (const auto& [v, uv] : state_->versions)
    if (v == version) {
      out = uv;
      return true;
    }
  return false;
}

void EditSession::snapshot(Atlas& atlas, std::vector<uint8_t>& seam_faces, std::vector<OrientationStroke>& strokes,
                           MapTextureOptions& options) const {
  State& st = *state_;
  const std::lock_guard<std::mutex> lock(st.edit_mutex);
  atlas = st.map.atlas;
  seam_faces = st.seam;
  strokes = st.strokes;
  options = st.options;
}

const Mesh& EditSession::mesh() const { return state_->mesh; }

}  // namespace tailor
