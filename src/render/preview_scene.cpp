// The CPU side of the preview pictures (preview_scene.h): inputs, scene, camera, vertex arrays,
// generated textures, legend and read-back. The public names of the views and up axes too.
#include "render/preview_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "render/preview_colors.h"
#include "tailor/export.h"
#include "tailor/metrics.h"
#include "tailor/render.h"
#include "tailor/topology.h"

namespace tailor {
namespace internal {
namespace {

constexpr int kMaxOutputSide = 8192;

std::array<float, 3> face_normal(const Mesh& mesh, size_t f) {
  const float* a = &mesh.positions[3 * size_t{mesh.indices[3 * f]}];
  const float* b = &mesh.positions[3 * size_t{mesh.indices[3 * f + 1]}];
  const float* c = &mesh.positions[3 * size_t{mesh.indices[3 * f + 2]}];
  const float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const float e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
}

bool same_uv(std::span<const float> uv, size_t c0, size_t c1) {
  return uv[2 * c0] == uv[2 * c1] && uv[2 * c0 + 1] == uv[2 * c1 + 1];
}

//! Edge e of face f and its opposite edge agree on the UVs of both end points.
bool uv_continuous(std::span<const float> uv, uint32_t e, uint32_t o) {
  const size_t f = e / 3, g = o / 3;
  const size_t a0 = 3 * f + e % 3, a1 = 3 * f + (e % 3 + 1) % 3;
  const size_t b0 = 3 * g + o % 3, b1 = 3 * g + (o % 3 + 1) % 3;
  // The opposite edge runs the other way: its start is our end.
  return same_uv(uv, a0, b1) && same_uv(uv, a1, b0);
}

std::string ratio_label(double ratio) {
  std::array<char, 32> buf{};
  std::snprintf(buf.data(), buf.size(), "%.3gx", ratio);
  return buf.data();
}

}  // namespace

Status check_inputs(const Mesh& mesh, std::span<const float> corner_uv, std::span<const uint32_t> patch,
                    const Image* texture, const PreviewMaterial& material, const RenderOptions& o) {
  auto bad = [](const std::string& what) { return Status::error(ErrorCode::kInvalidArgument, "", what); };
  if (o.width < 16 || o.height < 16 || o.width > kMaxOutputSide || o.height > kMaxOutputSide) {
    return bad("preview size must be between 16 and " + std::to_string(kMaxOutputSide) + " pixels a side");
  }
  if (o.supersample < 1 || o.supersample > 4) return bad("supersample must be 1..4");
  if (!(o.fov_degrees >= 5.0f && o.fov_degrees <= 120.0f)) return bad("field of view must be 5..120 degrees");
  if (!(o.pitch_degrees >= -89.0f && o.pitch_degrees <= 89.0f)) return bad("pitch must be -89..89 degrees");
  if (!std::isfinite(o.yaw_degrees)) return bad("yaw must be finite");
  if (!(o.checker_squares > 0.0f && o.checker_squares < 1e6f))
    return bad("checker squares must be above 0 and below 1e6");
  if (!(o.distortion_range > 0.0f && o.distortion_range < 64.0f)) return bad("distortion range must be positive");
  if (mesh.empty()) return Status::error(ErrorCode::kInvalidMesh, "", "mesh has no faces");
  if (mesh.positions.size() % 3 != 0 || mesh.indices.size() % 3 != 0) {
    return Status::error(ErrorCode::kInvalidMesh, "", "mesh arrays are not multiples of 3");
  }
  const size_t vertices = mesh.vertex_count();
  for (size_t c = 0; c < mesh.indices.size(); ++c) {
    if (mesh.indices[c] >= vertices) {
      return Status::error(ErrorCode::kInvalidMesh, "", "vertex index out of range", "face " + std::to_string(c / 3));
    }
  }
  const size_t faces = mesh.face_count();
  if (!corner_uv.empty() && corner_uv.size() != 6 * faces) return bad("corner UVs must hold #F*3 by 2 floats");
  if (corner_uv.empty() && o.view != PreviewView::kPatches) {
    return bad(std::string("the ") + preview_view_name(o.view) + " view needs texture coordinates");
  }
  if (!patch.empty() && patch.size() != faces) return bad("patch ids must hold one id per face");
  if (o.view != PreviewView::kTexture) return Status::ok();
  const auto consistent = [](const Image& image) {
    return image.channels >= 1 && image.channels <= 4 && image.width >= 1 && image.height >= 1 &&
           image.width <= kMaxImageSide && image.height <= kMaxImageSide &&
           image.pixels.size() == static_cast<size_t>(image.width) * static_cast<size_t>(image.height) *
                                      static_cast<size_t>(image.channels);
  };
  if (texture != nullptr && !consistent(*texture)) {
    return Status::error(ErrorCode::kInvalidImage, "", "texture image is empty or inconsistent");
  }
  if (material.normal != nullptr && (!consistent(*material.normal) || material.normal->channels < 3)) {
    return Status::error(ErrorCode::kInvalidImage, "", "normal map is empty, inconsistent or not RGB");
  }
  if (material.occlusion != nullptr && !consistent(*material.occlusion)) {
    return Status::error(ErrorCode::kInvalidImage, "", "occlusion map is empty or inconsistent");
  }
  if (!material.corner_tangents.empty()) {
    if (material.corner_tangents.size() != 4 * mesh.indices.size()) return bad("tangents must hold #F*3 by 4 floats");
    for (const float t : material.corner_tangents)
      if (!std::isfinite(t)) return bad("tangents must be finite");
  }
  return Status::ok();
}

// === Geometry set-up =============================================================================

Framing frame_mesh(const Mesh& mesh) {
  std::array<double, 3> lo = {HUGE_VAL, HUGE_VAL, HUGE_VAL};
  std::array<double, 3> hi = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const uint32_t v : mesh.indices) {
    for (size_t k = 0; k < 3; ++k) {
      const double x = mesh.positions[3 * size_t{v} + k];
      lo[k] = std::min(lo[k], x);
      hi[k] = std::max(hi[k], x);
    }
  }
  Framing f;
  for (size_t k = 0; k < 3; ++k) f.center[k] = 0.5 * (lo[k] + hi[k]);
  double r2 = 0.0;
  for (const uint32_t v : mesh.indices) {
    double d2 = 0.0;
    for (size_t k = 0; k < 3; ++k) {
      const double d = mesh.positions[3 * size_t{v} + k] - f.center[k];
      d2 += d * d;
    }
    r2 = std::max(r2, d2);
  }
  f.radius = r2 > 0.0 ? std::sqrt(r2) : 1.0;
  return f;
}

std::vector<float> vertex_normals(const Mesh& mesh) {
  std::vector<float> normals(mesh.positions.size(), 0.0f);
  const size_t faces = mesh.face_count();
  for (size_t f = 0; f < faces; ++f) {
    const auto n = face_normal(mesh, f);
    for (size_t k = 0; k < 3; ++k) {
      float* dst = &normals[3 * size_t{mesh.indices[3 * f + k]}];
      dst[0] += n[0];
      dst[1] += n[1];
      dst[2] += n[2];
    }
  }
  for (size_t v = 0; v < normals.size(); v += 3) {
    const float len =
        std::sqrt(normals[v] * normals[v] + normals[v + 1] * normals[v + 1] + normals[v + 2] * normals[v + 2]);
    if (len > 0.0f) {
      normals[v] /= len;
      normals[v + 1] /= len;
      normals[v + 2] /= len;
    }
  }
  return normals;
}

// === Patches and seams ===========================================================================

std::vector<float> seam_lines(const Mesh& mesh, const Topology& topology, std::span<const float> uv,
                              std::span<const uint32_t> patch, const Framing& frame) {
  std::vector<float> lines;
  const size_t corners = mesh.indices.size();
  auto push = [&](size_t corner) {
    const float* p = &mesh.positions[3 * size_t{mesh.indices[corner]}];
    for (size_t k = 0; k < 3; ++k) lines.push_back(static_cast<float>(p[k] - frame.center[k]));
  };
  for (uint32_t e = 0; e < corners; ++e) {
    const uint32_t o = topology.opposite[e];
    bool seam = o == kInvalid;
    if (!seam && o > e) {
      seam = (!patch.empty() && patch[e / 3] != patch[o / 3]) || (!uv.empty() && !uv_continuous(uv, e, o));
    }
    if (!seam) continue;
    const size_t f = e / 3;
    push(3 * f + e % 3);
    push(3 * f + (e % 3 + 1) % 3);
  }
  return lines;
}

// Visible and invisible seam edges (classify_seam_edges on the UVs in pixels of the texture size)
// as two line sets.
void seam_class_lines(const Mesh& mesh, const Topology& topology, std::span<const float> uv_repeats,
                      const RenderOptions& options, PreviewScene& scene) {
  const float w = static_cast<float>(options.seam_texture_px > 0 ? options.seam_texture_px : scene.texture_width);
  const float h = static_cast<float>(options.seam_texture_px > 0 ? options.seam_texture_px : scene.texture_height);
  std::vector<float> uv_px(uv_repeats.size());
  for (size_t c = 0; c < uv_px.size(); c += 2) {
    uv_px[c] = uv_repeats[c] * w;
    uv_px[c + 1] = uv_repeats[c + 1] * h;
  }
  MetricsOptions metrics;
  metrics.texture_width_px = w;
  metrics.texture_height_px = h;
  metrics.symmetry = options.seam_symmetry == 4 && w == h ? 4 : 1;
  std::vector<uint8_t> seam_class;
  classify_seam_edges(mesh, topology, uv_px, metrics, seam_class);
  for (size_t e = 0; e < seam_class.size(); ++e) {
    const uint32_t o = topology.opposite[e];
    if (seam_class[e] == 0 || o < e) continue;
    std::vector<float>& lines = seam_class[e] == 2 ? scene.lines : scene.invisible_lines;
    const size_t f = e / 3;
    for (const size_t corner : {3 * f + e % 3, 3 * f + (e % 3 + 1) % 3}) {
      const float* p = &mesh.positions[3 * size_t{mesh.indices[corner]}];
      for (size_t k = 0; k < 3; ++k) lines.push_back(static_cast<float>(p[k] - scene.frame.center[k]));
    }
  }
}

// === Per-face colours ============================================================================

std::vector<Rgb> distortion_colors(const Mesh& mesh, std::span<const float> uv, float range) {
  std::vector<float> ratio;
  face_area_stretch(mesh, uv, ratio);
  std::vector<Rgb> colors(ratio.size());
  for (size_t f = 0; f < ratio.size(); ++f) {
    // A collapsed UV triangle (ratio 0) is infinitely shrunk: heat_color clamps it to the cold end.
    const float l = ratio[f] > 0.0f ? std::log2(ratio[f]) : -1e9f;
    colors[f] = internal::heat_color(l / range);
  }
  return colors;
}

// === The scene of one view =======================================================================

void prepare_scene(const Mesh& mesh, std::span<const float> corner_uv, std::span<const uint32_t> patch,
                   const RenderOptions& options, PreviewScene& scene) {
  scene.frame = frame_mesh(mesh);
  scene.normals = vertex_normals(mesh);
  scene.patch_ids = patch;
  if (options.view == PreviewView::kPatches) {
    const bool need_topology = options.draw_seams || (patch.empty() && !corner_uv.empty());
    Topology topology;
    if (need_topology) topology = build_topology(mesh);
    if (patch.empty() && !corner_uv.empty()) {
      derive_patches(mesh, topology, corner_uv, scene.derived);
      scene.patch_ids = scene.derived;
    }
    if (options.draw_seams) scene.lines = seam_lines(mesh, topology, corner_uv, scene.patch_ids, scene.frame);
  } else if (options.view == PreviewView::kDistortion) {
    scene.face_colors = distortion_colors(mesh, corner_uv, options.distortion_range);
  } else if (options.view == PreviewView::kSeams) {
    scene.face_colors.assign(mesh.face_count(), internal::kSeamsSurface);
    seam_class_lines(mesh, build_topology(mesh), corner_uv, options, scene);
  }
}

// === Matrices (column-major, as glLoadMatrixf wants) =============================================

Mat4 perspective(double fovy_radians, double aspect, double near_plane, double far_plane) {
  const double f = 1.0 / std::tan(fovy_radians / 2.0);
  Mat4 m{};
  m[0] = static_cast<float>(f / aspect);
  m[5] = static_cast<float>(f);
  m[10] = static_cast<float>((far_plane + near_plane) / (near_plane - far_plane));
  m[11] = -1.0f;
  m[14] = static_cast<float>(2.0 * far_plane * near_plane / (near_plane - far_plane));
  return m;
}

Mat4 look_at(const std::array<double, 3>& eye) {
  // Looking at the origin with +y up.
  std::array<double, 3> fwd = {-eye[0], -eye[1], -eye[2]};
  const double fl = std::sqrt(fwd[0] * fwd[0] + fwd[1] * fwd[1] + fwd[2] * fwd[2]);
  for (double& x : fwd) x /= fl;
  std::array<double, 3> side = {fwd[1] * 0.0 - fwd[2] * 1.0, fwd[2] * 0.0 - fwd[0] * 0.0, fwd[0] * 1.0 - fwd[1] * 0.0};
  const double sl = std::sqrt(side[0] * side[0] + side[1] * side[1] + side[2] * side[2]);
  for (double& x : side) x /= sl;
  const std::array<double, 3> up = {side[1] * fwd[2] - side[2] * fwd[1], side[2] * fwd[0] - side[0] * fwd[2],
                                    side[0] * fwd[1] - side[1] * fwd[0]};
  Mat4 m{};
  for (size_t k = 0; k < 3; ++k) {
    m[4 * k + 0] = static_cast<float>(side[k]);
    m[4 * k + 1] = static_cast<float>(up[k]);
    m[4 * k + 2] = static_cast<float>(-fwd[k]);
  }
  m[12] = static_cast<float>(-(side[0] * eye[0] + side[1] * eye[1] + side[2] * eye[2]));
  m[13] = static_cast<float>(-(up[0] * eye[0] + up[1] * eye[1] + up[2] * eye[2]));
  m[14] = static_cast<float>(fwd[0] * eye[0] + fwd[1] * eye[1] + fwd[2] * eye[2]);
  m[15] = 1.0f;
  return m;
}

Mat4 up_rotation(UpAxis up) {
  // Rows of the 3x3 part: new (x, y, z) from old (x, y, z).
  std::array<std::array<float, 3>, 3> r{};
  switch (up) {
    case UpAxis::kPosY: r = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}; break;
    case UpAxis::kPosZ: r = {{{1, 0, 0}, {0, 0, 1}, {0, -1, 0}}}; break;
    case UpAxis::kPosX: r = {{{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}}; break;
    case UpAxis::kNegY: r = {{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}}; break;
    case UpAxis::kNegZ: r = {{{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}}; break;
    case UpAxis::kNegX: r = {{{0, 1, 0}, {-1, 0, 0}, {0, 0, 1}}}; break;
  }
  Mat4 m{};
  for (size_t row = 0; row < 3; ++row)
    for (size_t col = 0; col < 3; ++col) m[4 * col + row] = r[row][col];
  m[15] = 1.0f;
  return m;
}

Mat4 orthographic(double width, double height) {
  Mat4 m{};
  m[0] = static_cast<float>(2.0 / width);
  m[5] = static_cast<float>(2.0 / height);
  m[10] = -1.0f;
  m[12] = -1.0f;
  m[13] = -1.0f;
  m[15] = 1.0f;
  return m;
}

Camera place_camera(const Framing& frame, const RenderOptions& options, int band) {
  // Camera: a 3/4 view from above, far enough that the bounding sphere fits both ways.
  const double aspect = static_cast<double>(options.width) / (options.height - band);
  const double fovy = options.fov_degrees * std::numbers::pi / 180.0;
  const double half_fov = std::min(fovy / 2.0, std::atan(std::tan(fovy / 2.0) * aspect));
  const double distance = frame.radius / std::sin(half_fov) * 1.02;
  const double yaw = options.yaw_degrees * std::numbers::pi / 180.0;
  const double pitch = options.pitch_degrees * std::numbers::pi / 180.0;
  const std::array<double, 3> eye = {distance * std::cos(pitch) * std::sin(yaw), distance * std::sin(pitch),
                                     distance * std::cos(pitch) * std::cos(yaw)};
  const double near_plane = std::max(distance - frame.radius * 1.05, distance * 1e-3);
  const double far_plane = distance + frame.radius * 1.05;
  Camera camera;
  camera.projection = perspective(fovy, aspect, near_plane, far_plane);
  camera.view = look_at(eye);
  camera.turn = up_rotation(options.up);
  return camera;
}

// === Textures ====================================================================================

Image checker_image(Rgb dark, Rgb light) {
  Image img;
  img.width = img.height = 2 * kCheckerTexels;
  img.channels = 3;
  img.pixels.resize(static_cast<size_t>(img.width) * static_cast<size_t>(img.height) * 3);
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const bool odd = ((x / kCheckerTexels) + (y / kCheckerTexels)) % 2 == 1;
      const Rgb& c = odd ? dark : light;
      const size_t at = (static_cast<size_t>(y) * static_cast<size_t>(img.width) + static_cast<size_t>(x)) * 3;
      std::copy(c.begin(), c.end(), img.pixels.begin() + static_cast<std::ptrdiff_t>(at));
    }
  }
  return img;
}

Image half_size(const Image& src) {
  Image dst;
  dst.width = std::max(1, src.width / 2);
  dst.height = std::max(1, src.height / 2);
  dst.channels = src.channels;
  const size_t ch = static_cast<size_t>(src.channels);
  dst.pixels.resize(static_cast<size_t>(dst.width) * static_cast<size_t>(dst.height) * ch);
  const auto at = [&](int x, int y) {
    x = std::min(x, src.width - 1);
    y = std::min(y, src.height - 1);
    return (static_cast<size_t>(y) * static_cast<size_t>(src.width) + static_cast<size_t>(x)) * ch;
  };
  for (int y = 0; y < dst.height; ++y) {
    for (int x = 0; x < dst.width; ++x) {
      const size_t a = at(2 * x, 2 * y), b = at(2 * x + 1, 2 * y), c = at(2 * x, 2 * y + 1),
                   d = at(2 * x + 1, 2 * y + 1);
      const size_t out = (static_cast<size_t>(y) * static_cast<size_t>(dst.width) + static_cast<size_t>(x)) * ch;
      for (size_t k = 0; k < ch; ++k) {
        const int sum = src.pixels[a + k] + src.pixels[b + k] + src.pixels[c + k] + src.pixels[d + k];
        dst.pixels[out + k] = static_cast<uint8_t>((sum + 2) / 4);
      }
    }
  }
  return dst;
}

// === Vertex arrays ===============================================================================

SplitSurface split_surface(const Mesh& mesh, std::span<const float> key, bool key_is_uv,
                           std::span<const float> vertex_normal, const Framing& frame,
                           std::span<const float> corner_tangent) {
  SplitMesh split;
  split_vertices(mesh, key, split);
  const size_t count = split.xref.size();
  std::vector<float> positions(3 * count), normals(3 * count), texcoords;
  std::vector<uint8_t> colors;
  for (size_t s = 0; s < count; ++s) {
    const size_t v = split.xref[s];
    for (size_t d = 0; d < 3; ++d) {
      positions[3 * s + d] = static_cast<float>(split.positions[3 * s + d] - frame.center[d]);
      normals[3 * s + d] = vertex_normal[3 * v + d];
    }
  }
  if (key_is_uv) {
    texcoords.resize(2 * count);
    for (size_t s = 0; s < count; ++s) {
      // Mesh UVs have v up; the image is uploaded top row first, so t runs downwards.
      texcoords[2 * s] = split.uvs[2 * s];
      texcoords[2 * s + 1] = 1.0f - split.uvs[2 * s + 1];
    }
  } else {
    colors.resize(4 * count);
    for (size_t s = 0; s < count; ++s) {
      const auto id = static_cast<uint32_t>(split.uvs[2 * s]) | static_cast<uint32_t>(split.uvs[2 * s + 1]) << 24;
      const Rgb c = internal::patch_color(id);
      colors[4 * s] = c[0];
      colors[4 * s + 1] = c[1];
      colors[4 * s + 2] = c[2];
      colors[4 * s + 3] = 255;
    }
  }
  // Corners of one split vertex share its UV; a file's tangents may still differ there (hard edges):
  // their sum is the vertex's, the shader projects it into the tangent plane.
  std::vector<float> tangents;
  if (!corner_tangent.empty()) {
    tangents.assign(4 * count, 0.0f);
    for (size_t c = 0; c < split.indices.size(); ++c) {
      float* t = &tangents[4 * size_t{split.indices[c]}];
      const float* in = &corner_tangent[4 * c];
      t[0] += in[0], t[1] += in[1], t[2] += in[2];
      t[3] += in[3] < 0.0f ? -1.0f : 1.0f;
    }
    for (size_t s = 0; s < count; ++s) tangents[4 * s + 3] = tangents[4 * s + 3] < 0.0f ? -1.0f : 1.0f;
  }
  return {std::move(split),     std::move(positions), std::move(normals),
          std::move(texcoords), std::move(tangents),  std::move(colors)};
}

std::vector<float> patch_keys(const Mesh& mesh, std::span<const uint32_t> patch) {
  // A patch id as two floats that hold it exactly (24 + 8 bits), so splitting compares ids exactly.
  std::vector<float> key(2 * mesh.indices.size(), 0.0f);
  for (size_t c = 0; c < mesh.indices.size(); ++c) {
    const uint32_t id = patch.empty() ? 0 : patch[c / 3];
    key[2 * c] = static_cast<float>(id & 0xFFFFFFu);
    key[2 * c + 1] = static_cast<float>(id >> 24);
  }
  return key;
}

void fill_face_colored_batch(const Mesh& mesh, const std::vector<Rgb>& face_colors,
                             std::span<const float> vertex_normal, const Framing& frame, size_t start, size_t count,
                             std::vector<float>& pos, std::vector<float>& nor, std::vector<uint8_t>& col) {
  for (size_t i = 0; i < count; ++i) {
    const size_t f = start + i;
    const Rgb color = face_colors[f];
    for (size_t k = 0; k < 3; ++k) {
      const size_t v = mesh.indices[3 * f + k];
      const size_t slot = 3 * i + k;
      for (size_t d = 0; d < 3; ++d) {
        pos[3 * slot + d] = static_cast<float>(mesh.positions[3 * v + d] - frame.center[d]);
        nor[3 * slot + d] = vertex_normal[3 * v + d];
      }
      col[4 * slot] = color[0];
      col[4 * slot + 1] = color[1];
      col[4 * slot + 2] = color[2];
      col[4 * slot + 3] = 255;
    }
  }
}

// === Legend ======================================================================================

LegendBox legend_box(int width, int height) {
  LegendBox box;
  box.text_scale = std::max(1, height / 300);
  box.width = width / 2;
  box.height = std::max(6, height / 40);
  box.x = (width - box.width) / 2;
  box.y = height - box.height - 7 * box.text_scale - std::max(8, height / 40);
  return box;
}

LegendBar legend_bar(const LegendBox& box, int target_height, int scale) {
  constexpr int kSteps = 64;
  const float x0 = static_cast<float>(box.x * scale);
  const float w = static_cast<float>(box.width * scale);
  // GL's y runs upwards.
  const float y_top = static_cast<float>(target_height - box.y * scale);
  const float y_bottom = y_top - static_cast<float>(box.height * scale);
  const float pad = static_cast<float>(scale * std::max(1, box.height / 6));
  LegendBar bar;
  std::vector<float>& xy = bar.xy;
  std::vector<uint8_t>& rgba = bar.rgba;
  auto vertex = [&](float x, float y, Rgb c) {
    xy.push_back(x);
    xy.push_back(y);
    rgba.insert(rgba.end(), {c[0], c[1], c[2], 255});
  };
  // Frame (two triangles), then the bar as a strip whose colours step along the heat map.
  vertex(x0 - pad, y_bottom - pad, kLegendInk);
  vertex(x0 + w + pad, y_bottom - pad, kLegendInk);
  vertex(x0 - pad, y_top + pad, kLegendInk);
  vertex(x0 + w + pad, y_top + pad, kLegendInk);
  bar.frame_vertices = xy.size() / 2;
  for (int i = 0; i <= kSteps; ++i) {
    const float t = static_cast<float>(i) / kSteps;
    const Rgb c = internal::heat_color(2.0f * t - 1.0f);
    vertex(x0 + t * w, y_bottom, c);
    vertex(x0 + t * w, y_top, c);
  }
  return bar;
}

void draw_legend_text(const LegendBox& box, float range, Image& out) {
  const int s = box.text_scale;
  const int y = box.y + box.height + std::max(3, box.height / 3);
  const std::string lo = ratio_label(std::exp2(-static_cast<double>(range)));
  const std::string mid = "1x";
  const std::string hi = ratio_label(std::exp2(static_cast<double>(range)));
  internal::draw_text(out, lo, box.x, y, s, kLegendInk);
  internal::draw_text(out, mid, box.x + (box.width - internal::text_width(mid, s)) / 2, y, s, kLegendInk);
  internal::draw_text(out, hi, box.x + box.width - internal::text_width(hi, s), y, s, kLegendInk);
}

// === Read-back ===================================================================================

void resolve(const std::vector<uint8_t>& rgba, int target_width, int scale, Image& out) {
  const int n = scale * scale;
  for (int y = 0; y < out.height; ++y) {
    const int src_y0 = (out.height - 1 - y) * scale;
    for (int x = 0; x < out.width; ++x) {
      std::array<int, 3> sum{};
      for (int dy = 0; dy < scale; ++dy) {
        const size_t row = static_cast<size_t>(src_y0 + dy) * static_cast<size_t>(target_width);
        for (int dx = 0; dx < scale; ++dx) {
          const size_t at = (row + static_cast<size_t>(x * scale + dx)) * 4;
          for (size_t c = 0; c < 3; ++c) sum[c] += rgba[at + c];
        }
      }
      const size_t dst = (static_cast<size_t>(y) * static_cast<size_t>(out.width) + static_cast<size_t>(x)) * 3;
      for (size_t c = 0; c < 3; ++c) out.pixels[dst + c] = static_cast<uint8_t>((sum[c] + n / 2) / n);
    }
  }
}

}  // namespace internal

bool preview_view_from_name(std::string_view name, PreviewView& view) {
  for (const PreviewView v : {PreviewView::kTexture, PreviewView::kPatches, PreviewView::kDistortion,
                              PreviewView::kChecker, PreviewView::kSeams}) {
    if (name == preview_view_name(v)) {
      view = v;
      return true;
    }
  }
  return false;
}

bool up_axis_from_name(std::string_view name, UpAxis& up) {
  if (!name.empty() && name.front() == '+') name.remove_prefix(1);
  constexpr std::pair<std::string_view, UpAxis> kNames[] = {{"y", UpAxis::kPosY},  {"z", UpAxis::kPosZ},
                                                            {"x", UpAxis::kPosX},  {"-y", UpAxis::kNegY},
                                                            {"-z", UpAxis::kNegZ}, {"-x", UpAxis::kNegX}};
  for (const auto& [text, axis] : kNames) {
    if (name == text) {
      up = axis;
      return true;
    }
  }
  return false;
}

const char* preview_view_name(PreviewView view) {
  switch (view) {
    case PreviewView::kTexture: return "texture";
    case PreviewView::kPatches: return "patches";
    case PreviewView::kDistortion: return "distortion";
    case PreviewView::kChecker: return "checker";
    case PreviewView::kSeams: return "seams";
  }
  return "texture";
}

}  // namespace tailor
