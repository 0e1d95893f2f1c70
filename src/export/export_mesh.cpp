// export_mesh: validation, vertex splitting and normals shared by the .glb, .obj and .ply writers.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <new>
#include <span>
#include <string>
#include <vector>

#include "export/writers.h"
#include "tailor/export.h"
#include "util/atomic_file.h"
#include "util/huge_pages.h"
#include "util/parallel_chunks.h"
#include "util/simd.h"

namespace tailor {
namespace internal {

Status read_texture_bytes(const std::string& path, std::string& bytes, std::string& mime_type) {
  TAILOR_RETURN_IF_ERROR(read_file(path, bytes));
  static constexpr unsigned char kPng[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  static constexpr unsigned char kJpeg[3] = {0xff, 0xd8, 0xff};
  if (bytes.size() >= sizeof kPng && std::memcmp(bytes.data(), kPng, sizeof kPng) == 0) {
    mime_type = "image/png";
  } else if (bytes.size() >= sizeof kJpeg && std::memcmp(bytes.data(), kJpeg, sizeof kJpeg) == 0) {
    mime_type = "image/jpeg";
  } else {
    bytes.clear();
    return Status::error(ErrorCode::kInvalidImage, path, "texture is neither PNG nor JPEG");
  }
  return Status::ok();
}

void append_float(std::string& out, float value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

namespace {

// A file name a .mtl or .ply header can hold: whitespace splits a map_Kd in most readers and a
// newline ends the line, so both become '_'.
std::string portable_file_name(const std::string& name) {
  std::string out = name;
  for (char& c : out)
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f') c = '_';
  return out;
}

// Whether `path` is a regular file holding exactly `bytes`.
bool holds_bytes(const std::filesystem::path& path, const std::string& bytes) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error) || std::filesystem::file_size(path, error) != bytes.size() ||
      error)
    return false;
  std::string existing;
  return read_file(path.string(), existing).is_ok() && existing == bytes;
}

}  // namespace

std::vector<std::string> names_in_folder(const std::filesystem::path& folder, const std::vector<std::string>& others,
                                         std::initializer_list<std::string> own) {
  namespace fs = std::filesystem;
  // One folder however it is spelt: the same directory when both exist (symlinks, relative and
  // absolute names), else the same normalised absolute path, without a trailing separator.
  const auto spelt = [](const fs::path& p) {
    std::error_code error;
    fs::path normal = fs::absolute(p, error).lexically_normal();
    if (!normal.has_filename() && normal.has_parent_path() && normal != normal.root_path())
      normal = normal.parent_path();
    return normal;
  };
  const auto same_folder = [&spelt](const fs::path& a, const fs::path& b) {
    std::error_code error;
    const bool same = fs::equivalent(a, b, error);
    return error ? spelt(a) == spelt(b) : same;
  };
  const fs::path here = folder.empty() ? fs::path(".") : folder;
  std::vector<std::string> names(own);
  for (const std::string& other : others) {
    const fs::path path(other);
    if (same_folder(here, path.has_parent_path() ? path.parent_path() : fs::path(".")))
      names.push_back(path.filename().string());
  }
  return names;
}

Status texture_name_beside(const std::string& texture_path, const std::string& bytes,
                           const std::filesystem::path& out_dir, std::span<const std::string> taken, std::string& name,
                           bool& copy) {
  copy = false;
  const std::filesystem::path source(texture_path);
  const std::filesystem::path folder = out_dir.empty() ? std::filesystem::path(".") : out_dir;
  const std::string wanted = portable_file_name(source.filename().string());
  std::error_code error;
  if (wanted == source.filename().string() && std::filesystem::equivalent(source, folder / wanted, error)) {
    name = wanted;  // the texture already lies beside the output
    return Status::ok();
  }
  const std::string stem = std::filesystem::path(wanted).stem().string();
  const std::string extension = std::filesystem::path(wanted).extension().string();
  constexpr int kMaxCandidates = 1000;
  for (int k = 1; k <= kMaxCandidates; ++k) {
    const std::string candidate = k == 1 ? wanted : stem + "-" + std::to_string(k) + extension;
    const std::filesystem::path target = folder / candidate;
    if (std::find(taken.begin(), taken.end(), candidate) != taken.end()) continue;
    if (holds_bytes(target, bytes)) {  // the same picture: referenced, not written again
      name = candidate;
      return Status::ok();
    }
    if (std::filesystem::symlink_status(target, error).type() != std::filesystem::file_type::not_found) continue;
    name = candidate;
    copy = true;
    return Status::ok();
  }
  return Status::error(ErrorCode::kIo, (folder / wanted).string(),
                       "cannot place the texture beside the output: " + std::to_string(kMaxCandidates) +
                           " files of that name already hold other pictures");
}

}  // namespace internal

namespace {

enum class ExportFormat { kUnknown, kGlb, kObj, kPly };

ExportFormat export_format(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return ExportFormat::kUnknown;
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  if (ext == "glb") return ExportFormat::kGlb;
  if (ext == "obj") return ExportFormat::kObj;
  if (ext == "ply") return ExportFormat::kPly;
  return ExportFormat::kUnknown;
}

// Area-weighted normals per source vertex (the unnormalised face normal is 2 * area * n), so that
// shading stays smooth across UV seams. Isolated or degenerate vertices get +z.
void vertex_normals(const Mesh& mesh, std::vector<float>& normals) {
  const size_t nv = mesh.vertex_count();
  // calloc'd: fresh pages come zeroed from the kernel, a vector would zero them again.
  const internal::HugeArray<double> sum_array = internal::huge_zeroed<double>(3 * nv);
  double* sum = sum_array.get();
  const float* positions = mesh.positions.data();
  const uint32_t* indices = mesh.indices.data();
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    const uint32_t* t = &indices[3 * f];
    const float* a = &positions[3 * size_t{t[0]}];
    const float* b = &positions[3 * size_t{t[1]}];
    const float* c = &positions[3 * size_t{t[2]}];
#if TAILOR_SSE2
    // The scalar code below with x and y in one register: the same IEEE operations in the same
    // order per component, so the same bits, in about half the instructions.
    auto load_xy = [](const float* p) {
      return _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
    };
    auto load_z = [](const float* p) { return _mm_cvtss_sd(_mm_setzero_pd(), _mm_load_ss(p + 2)); };
    const __m128d a_xy = load_xy(a), a_z = load_z(a);
    const __m128d e1_xy = _mm_sub_pd(load_xy(b), a_xy), e1_z = _mm_sub_sd(load_z(b), a_z);
    const __m128d e2_xy = _mm_sub_pd(load_xy(c), a_xy), e2_z = _mm_sub_sd(load_z(c), a_z);
    // (n0, n1) = (e1y, e1z) * (e2z, e2x) - (e1z, e1x) * (e2y, e2z); n2 = e1x * e2y - e1y * e2x.
    const __m128d n_xy = _mm_sub_pd(_mm_mul_pd(_mm_shuffle_pd(e1_xy, e1_z, 1), _mm_shuffle_pd(e2_z, e2_xy, 0)),
                                    _mm_mul_pd(_mm_shuffle_pd(e1_z, e1_xy, 0), _mm_shuffle_pd(e2_xy, e2_z, 1)));
    const __m128d n_z =
        _mm_sub_sd(_mm_mul_sd(e1_xy, _mm_unpackhi_pd(e2_xy, e2_xy)), _mm_mul_sd(_mm_unpackhi_pd(e1_xy, e1_xy), e2_xy));
    for (int k = 0; k < 3; ++k) {  // one vertex at a time: a face may repeat a vertex
      double* s = &sum[3 * size_t{t[k]}];
      _mm_storeu_pd(s, _mm_add_pd(_mm_loadu_pd(s), n_xy));
      _mm_store_sd(s + 2, _mm_add_sd(_mm_load_sd(s + 2), n_z));
    }
#else
    const double e1[3] = {double{b[0]} - a[0], double{b[1]} - a[1], double{b[2]} - a[2]};
    const double e2[3] = {double{c[0]} - a[0], double{c[1]} - a[1], double{c[2]} - a[2]};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i) sum[3 * size_t{t[k]} + i] += n[i];
#endif
  }
  internal::reserve_huge(normals, 3 * nv);
  normals.resize(3 * nv);
  for (size_t v = 0; v < nv; ++v) {
    const double* n = &sum[3 * v];
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (length > 0 && std::isfinite(length)) {
      for (int i = 0; i < 3; ++i) normals[3 * v + i] = static_cast<float>(n[i] / length);
    } else {
      normals[3 * v] = 0;
      normals[3 * v + 1] = 0;
      normals[3 * v + 2] = 1;
    }
  }
}

// True when every corner's vertex index is < vertex_count().
bool indices_in_range(const Mesh& mesh) {
  const uint32_t* idx = mesh.indices.data();
  const size_t n = mesh.indices.size();
  const size_t nv = mesh.vertex_count();
  if (nv == 0) return n == 0;
  if (nv > std::numeric_limits<uint32_t>::max()) return true;
  uint32_t largest = 0;
  for (size_t c = 0; c < n; ++c) largest = std::max(largest, idx[c]);
  return largest < nv;
}

// True when no coordinate is inf or NaN (all exponent bits set).
bool positions_finite(const Mesh& mesh) {
  const float* pos = mesh.positions.data();
  const size_t n = mesh.positions.size();
  uint32_t any = 0;
  for (size_t i = 0; i < n; ++i) {
    uint32_t bits;
    std::memcpy(&bits, pos + i, 4);
    any |= static_cast<uint32_t>((bits & 0x7f800000u) == 0x7f800000u);
  }
  return any == 0;
}

// Splits the vertices of `mesh` where corners of one vertex carry different values of the
// attributes `kept` (per corner): `out` gets the split positions and indices, `kept_out` the
// values per split vertex (those of the vertex's first corner). O(F): a chain of split vertices
// per source vertex, usually one or two long (hard edges, colour borders).
void split_on_attributes(const Mesh& mesh, const std::vector<const CornerAttribute*>& kept, Mesh& out,
                         std::vector<CornerAttribute>& kept_out) {
  const size_t corners = mesh.indices.size();
  std::vector<uint32_t> head(mesh.vertex_count(), kInvalid), next, first_corner;
  out.indices.resize(corners);
  auto same = [&](size_t a, size_t b) {
    for (const CornerAttribute* attribute : kept) {
      const size_t k = size_t(attribute->components);
      if (std::memcmp(&attribute->values[k * a], &attribute->values[k * b], k * sizeof(float)) != 0) return false;
    }
    return true;
  };
  for (size_t c = 0; c < corners; ++c) {
    const uint32_t v = mesh.indices[c];
    uint32_t id = head[v];
    while (id != kInvalid && !same(first_corner[id], c)) id = next[id];
    if (id == kInvalid) {
      id = static_cast<uint32_t>(first_corner.size());
      first_corner.push_back(static_cast<uint32_t>(c));
      next.push_back(head[v]);
      head[v] = id;
    }
    out.indices[c] = id;
  }
  const size_t nv = first_corner.size();
  out.positions.resize(3 * nv);
  for (size_t id = 0; id < nv; ++id)
    std::memcpy(&out.positions[3 * id], &mesh.positions[3 * size_t{mesh.indices[first_corner[id]]}], 12);
  kept_out.clear();
  for (const CornerAttribute* attribute : kept) {
    const size_t k = size_t(attribute->components);
    CornerAttribute& a = kept_out.emplace_back(CornerAttribute{attribute->name, attribute->components, {}});
    a.values.resize(k * nv);
    for (size_t id = 0; id < nv; ++id)
      std::memcpy(&a.values[k * id], &attribute->values[k * first_corner[id]], k * sizeof(float));
  }
}

// Sorts the faces of `mesh` by part into `out` (stable) and its corner UVs into `uv`, adding the part
// id as a corner attribute (its float's bits; named "" so that it is told apart), so that vertices
// are split where parts meet.
void sort_faces_by_part(const Mesh& mesh, std::span<const float> corner_uv, size_t part_count, Mesh& out,
                        std::vector<float>& uv, std::vector<uint32_t>& order) {
  const size_t nf = mesh.face_count();
  std::vector<size_t> start(part_count + 1, 0);
  for (uint32_t p : mesh.face_parts) ++start[p + 1];
  for (size_t p = 0; p < part_count; ++p) start[p + 1] += start[p];
  order.resize(nf);  // sorted position -> face
  for (size_t f = 0; f < nf; ++f) order[start[mesh.face_parts[f]]++] = static_cast<uint32_t>(f);
  out.positions = mesh.positions;
  out.indices.resize(3 * nf);
  uv.resize(6 * nf);
  out.face_parts.resize(nf);
  for (size_t i = 0; i < nf; ++i) {
    const size_t f = order[i];
    std::memcpy(&out.indices[3 * i], &mesh.indices[3 * f], 12);
    std::memcpy(&uv[6 * i], &corner_uv[6 * f], 24);
    out.face_parts[i] = mesh.face_parts[f];
  }
  for (const CornerAttribute& a : mesh.corner_attributes) {
    const size_t k = 3 * size_t(a.components);
    CornerAttribute& b = out.corner_attributes.emplace_back(CornerAttribute{a.name, a.components, {}});
    b.values.resize(a.values.size());
    for (size_t i = 0; i < nf; ++i) std::memcpy(&b.values[k * i], &a.values[k * order[i]], k * sizeof(float));
  }
  CornerAttribute& id = out.corner_attributes.emplace_back(CornerAttribute{"", 1, {}});
  id.values.resize(3 * nf);
  for (size_t c = 0; c < 3 * nf; ++c) {
    const uint32_t part = out.face_parts[c / 3];
    std::memcpy(&id.values[c], &part, 4);
  }
}

// The parts' ranges in the split mesh (faces sorted by part, vertices split on it and numbered
// in order of first corner, so each part's vertices follow those of the part before).
void part_ranges(const std::vector<uint32_t>& face_parts, const SplitMesh& split,
                 std::vector<internal::ExportPart>& parts) {
  const size_t nf = face_parts.size();
  size_t vertex_begin = 0;
  for (size_t f = 0; f < nf;) {
    internal::ExportPart part;
    part.part = face_parts[f];
    part.index_begin = 3 * f;
    part.vertex_begin = vertex_begin;
    uint32_t largest = 0;
    for (; f < nf && face_parts[f] == part.part; ++f)
      for (int k = 0; k < 3; ++k) largest = std::max(largest, split.indices[3 * f + size_t(k)]);
    part.index_end = 3 * f;
    part.vertex_end = size_t{largest} + 1;
    vertex_begin = part.vertex_end;
    parts.push_back(part);
  }
}

// Faces from which the normals get their own thread (below, starting it costs more than it saves).
constexpr size_t kThreadedFaces = 100000;

}  // namespace

std::string obj_material_path(const std::string& obj_path) {
  std::filesystem::path path(obj_path);
  std::string stem = path.stem().string();
  std::replace_if(
      stem.begin(), stem.end(), [](char c) { return c == ' ' || c == '\t'; }, '_');
  return path.replace_filename(stem + ".mtl").string();
}

Status check_uv_set(const Mesh& mesh, int uv_set, const std::string& path) {
  for (int set = 0; set < uv_set; ++set) {
    const std::string name = "TEXCOORD_" + std::to_string(set);
    if (std::none_of(mesh.corner_attributes.begin(), mesh.corner_attributes.end(),
                     [&](const CornerAttribute& a) { return a.name == name; }))
      return Status::error(ErrorCode::kInvalidArgument, path,
                           "the UVs would go to TEXCOORD_" + std::to_string(uv_set) + " but the mesh has no " + name +
                               " to keep below it (glTF numbers the sets from 0 without gaps)",
                           "use --uv-set " + std::to_string(set));
  }
  return Status::ok();
}

Status export_mesh(const std::string& path, const Mesh& mesh, const Atlas& atlas, const ExportOptions& options) {
  const ExportFormat format = export_format(path);
  if (format == ExportFormat::kUnknown)
    return Status::error(ErrorCode::kInvalidArgument, path, "unsupported output format (use .glb, .obj or .ply)");
  const size_t nf = mesh.face_count();
  if (nf == 0) return Status::error(ErrorCode::kInvalidArgument, path, "mesh has no face to export");
  if (atlas.corner_uv.size() != 6 * nf)
    return Status::error(ErrorCode::kInvalidArgument, path, "atlas does not match the mesh",
                         std::to_string(atlas.corner_uv.size()) + " UV floats for " + std::to_string(nf) + " faces");
  if (options.compression != MeshCompression::kNone && format != ExportFormat::kGlb)
    return Status::error(ErrorCode::kInvalidArgument, path, "compression needs a .glb output");
  if (options.uv_set < 0 || options.uv_set > 7)
    return Status::error(ErrorCode::kInvalidArgument, path, "the UV set must be 0 to 7");
  if (options.uv_set != 0 && format != ExportFormat::kGlb)
    return Status::error(ErrorCode::kInvalidArgument, path, "a UV set other than 0 needs a .glb output");
  TAILOR_RETURN_IF_ERROR(check_uv_set(mesh, options.uv_set, path));
  if (!options.material.empty() && format != ExportFormat::kGlb)
    return Status::error(ErrorCode::kInvalidArgument, path, "material maps need a .glb output");
  if (!options.image_uris.empty() && format != ExportFormat::kGlb)
    return Status::error(ErrorCode::kInvalidArgument, path, "images named by URI need a .glb output");
  if (!options.image_uris.color.empty() && options.texture_path.empty())
    return Status::error(ErrorCode::kInvalidArgument, path, "an image URI is given for the colour map but no texture");
  if (!options.image_uris.orm.empty() && !options.material.orm_roughness_metallic && !options.material.orm_occlusion)
    return Status::error(ErrorCode::kInvalidArgument, path,
                         "an image URI is given for the ORM map but it serves as neither metallicRoughness nor "
                         "occlusion");
  if (options.texture_width <= 0 || options.texture_height <= 0)
    return Status::error(ErrorCode::kInvalidArgument, path, "texture size must be positive");
  // Branch-free scans first (they vectorize); the exact culprit is looked for only on failure.
  if (!indices_in_range(mesh)) {
    for (size_t c = 0; c < mesh.indices.size(); ++c)
      if (mesh.indices[c] >= mesh.vertex_count())
        return Status::error(ErrorCode::kInvalidArgument, path, "vertex index out of range",
                             "corner " + std::to_string(c));
  }
  if (!positions_finite(mesh)) {
    for (size_t i = 0; i < mesh.positions.size(); ++i)
      if (!std::isfinite(mesh.positions[i]))
        return Status::error(ErrorCode::kInvalidArgument, path, "position is not finite",
                             "vertex " + std::to_string(i / 3));
  }

  // Pixels -> texture repeats, OBJ convention (t up); the glTF writer flips t itself. Scaled on the
  // fly inside the split (no array of repeats), which also finds the first non-finite UV.
  // The normals need only the mesh: on large meshes a second thread computes them during the split
  // (both results are the same whichever thread runs them).
  internal::ExportData data;
  data.mesh = &mesh;
  data.uv_set = options.uv_set;
  // A glTF scene's parts (.glb only): faces sorted by part, vertices split where parts meet, so
  // that each part becomes a primitive with its own vertex range.
  std::span<const float> corner_uv = atlas.corner_uv;
  std::vector<float> sorted_uv;
  std::vector<uint32_t> sorted_order;  // the input face of each sorted face (for error messages)
  const bool scene = format == ExportFormat::kGlb && !mesh.scene.empty() && mesh.face_parts.size() == nf;
  if (scene) {
    const SceneParts& parts = mesh.scene;
    for (const SceneParts::Part& part : parts.parts)
      if (part.instance >= parts.instances.size() ||
          (part.material != kInvalid && part.material >= parts.materials.size()))
        return Status::error(ErrorCode::kInvalidArgument, path, "scene part out of range");
    for (uint32_t p : mesh.face_parts)
      if (p >= parts.parts.size()) return Status::error(ErrorCode::kInvalidArgument, path, "face part out of range");
    sort_faces_by_part(mesh, atlas.corner_uv, parts.parts.size(), data.part_sorted, sorted_uv, sorted_order);
    corner_uv = sorted_uv;
    data.mesh = &data.part_sorted;
    data.scene = &parts;
  }
  const Mesh& input = *data.mesh;
  // The file's own attributes (glTF): the mapped UV set replaces its namesake; vertices split
  // where they differ, the input's NORMAL used instead of computed normals.
  std::vector<const CornerAttribute*> kept;
  const std::string mapped_set = "TEXCOORD_" + std::to_string(options.uv_set);
  for (const CornerAttribute& a : input.corner_attributes)
    if (a.name != mapped_set && (format == ExportFormat::kGlb || a.name == "NORMAL" || a.name == "COLOR_0"))
      kept.push_back(&a);
  bool input_normals = false;
  if (!kept.empty()) {
    split_on_attributes(input, kept, data.attribute_split, data.kept);
    data.mesh = &data.attribute_split;
    if (scene) data.kept.pop_back();  // the part ids (last): not written
    for (size_t i = 0; i < data.kept.size(); ++i)
      if (data.kept[i].name == "NORMAL") {
        data.normals = std::move(data.kept[i].values);
        for (size_t v = 0; v < data.normals.size(); v += 3) {  // unit length, as glTF wants
          float* n = &data.normals[v];
          const double length = std::sqrt(double{n[0]} * n[0] + double{n[1]} * n[1] + double{n[2]} * n[2]);
          if (length > 0 && std::isfinite(length)) {
            for (int k = 0; k < 3; ++k) n[k] = static_cast<float>(n[k] / length);
          } else {
            n[0] = 0, n[1] = 0, n[2] = 1;
          }
        }
        data.kept.erase(data.kept.begin() + static_cast<std::ptrdiff_t>(i));
        input_normals = true;
        break;
      }
  }
  const Mesh& source = *data.mesh;
  const bool want_normals = options.normals && format != ExportFormat::kPly && !input_normals;
  const double su = 1.0 / options.texture_width, sv = 1.0 / options.texture_height;
  size_t bad_corner = internal::kNoBadCorner;
  internal::run_beside(
      want_normals && nf >= kThreadedFaces,
      [&] {
        if (want_normals) vertex_normals(source, data.normals);
      },
      [&] { bad_corner = internal::split_vertices_scaled(source, corner_uv, su, sv, data.split); });
  if (bad_corner != internal::kNoBadCorner) {
    if (scene) bad_corner = 3 * size_t{sorted_order[bad_corner / 3]} + bad_corner % 3;  // the caller's corner id
    return Status::error(ErrorCode::kInvalidArgument, path, "UV is not finite", "corner " + std::to_string(bad_corner));
  }
  if (options.progress && !options.progress(internal::ExportProgress::kSplitShare))
    return internal::ExportProgress::cancelled(path);
  if (scene) part_ranges(data.part_sorted.face_parts, data.split, data.parts);

  if (format == ExportFormat::kGlb && options.has_normal_map() && !data.normals.empty())
    internal::compute_tangents(*data.mesh, data.split, data.normals, data.tangents);

  switch (format) {
    case ExportFormat::kGlb:
      return options.compression == MeshCompression::kNone ? internal::write_glb(path, data, options)
                                                           : internal::write_glb_compressed(path, data, options);
    case ExportFormat::kObj: return internal::write_obj(path, data, options);
    case ExportFormat::kPly: return internal::write_ply(path, data, options);
    case ExportFormat::kUnknown: break;
  }
  return Status::error(ErrorCode::kInvalidArgument, path, "unsupported output format");
}

Status corner_tangents(const Mesh& mesh, std::span<const float> corner_uv, std::vector<float>& tangents) {
  tangents.clear();
  const size_t corners = mesh.indices.size();
  if (corner_uv.size() != 2 * corners)
    return Status::error(ErrorCode::kInvalidArgument, "", "corner UVs must hold #F*3 by 2 floats");
  for (const uint32_t v : mesh.indices)
    if (v >= mesh.vertex_count()) return Status::error(ErrorCode::kInvalidMesh, "", "vertex index out of range");
  try {
    // As export_mesh: split on the UVs, area-weighted normals, the frames per split vertex.
    SplitMesh split;
    split_vertices(mesh, corner_uv, split);
    std::vector<float> normals, per_split;
    vertex_normals(mesh, normals);
    internal::compute_tangents(mesh, split, normals, per_split);
    tangents.resize(4 * corners);
    for (size_t c = 0; c < corners; ++c) std::copy_n(&per_split[4 * size_t{split.indices[c]}], 4, &tangents[4 * c]);
  } catch (const std::bad_alloc&) {
    tangents.clear();
    return Status::error(ErrorCode::kLimit, "", "out of memory while computing tangents");
  }
  return Status::ok();
}

}  // namespace tailor
