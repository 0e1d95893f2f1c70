// Headless preview pictures with Mesa's off-screen OpenGL (OSMesa on llvmpipe).
//
// The mesh is drawn as unindexed triangles (UVs and colours live per corner) from vertex buffer
// objects filled in batches, so memory stays bounded for any face count and no immediate mode is
// used. Patches and per-face area stretch come from metrics.h (one definition for eval and the
// pictures). Text of the legend is stamped on the CPU after read-back.
//
// The checker view is the classic stretch test of parameterisation papers, e.g. Sander, Snyder,
// Gortler, Hoppe, "Texture mapping progressive meshes", SIGGRAPH 2001; the heat map uses the end
// points of Moreland, "Diverging color maps for scientific visualization", ISVC 2009.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "render/preview_colors.h"
#include "tailor/export.h"
#include "tailor/metrics.h"
#include "tailor/render.h"
#include "tailor/topology.h"

namespace tailor {

using internal::Rgb;

namespace {

// Faces per vertex-buffer batch: 3 corners x (3+3 floats + 2 floats + 4 bytes) = 108 bytes a
// face, so ~28 MB of arrays at a time, few enough draw calls that batching costs nothing.
constexpr size_t kBatchFaces = size_t{1} << 18;
// Largest render target side after supersampling (llvmpipe allows 16384; memory is the limit).
constexpr int kMaxRenderSide = 8192;
constexpr int kMaxOutputSide = 8192;
constexpr Rgb kBackground = {236, 238, 242};
constexpr Rgb kSeamColor = {20, 20, 28};
constexpr Rgb kLegendInk = {30, 30, 36};
// Checker tiles: light/dark grey for the neutral stand-in texture, near black/white for the checker view.
constexpr Rgb kNeutralDark = {150, 150, 150};
constexpr Rgb kNeutralLight = {205, 205, 205};
constexpr Rgb kCheckerDark = {35, 35, 40};
constexpr Rgb kCheckerLight = {240, 240, 240};
constexpr int kCheckerTexels = 64;  // per checker square in the generated texture (2x2 squares)

// === OSMesa context, created and destroyed per call =============================================

class OffscreenContext {
 public:
  OffscreenContext() = default;
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;
  ~OffscreenContext() {
    if (context_ != nullptr) OSMesaDestroyContext(context_);
  }

  bool create(int width, int height) {
    context_ = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
    if (context_ == nullptr) return false;
    buffer_.assign(static_cast<size_t>(width) * static_cast<size_t>(height) * 4, 0);
    return OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width, height) == GL_TRUE;
  }

  //! RGBA, bottom row first (OSMesa's default).
  const std::vector<uint8_t>& pixels() const { return buffer_; }

 private:
  OSMesaContext context_ = nullptr;
  std::vector<uint8_t> buffer_;
};

// === Geometry set-up =============================================================================

struct Framing {
  std::array<double, 3> center{};
  double radius = 1.0;
};

//! Centre of the bounding box and the radius of the sphere around it holding every used vertex.
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

std::array<float, 3> face_normal(const Mesh& mesh, size_t f) {
  const float* a = &mesh.positions[3 * size_t{mesh.indices[3 * f]}];
  const float* b = &mesh.positions[3 * size_t{mesh.indices[3 * f + 1]}];
  const float* c = &mesh.positions[3 * size_t{mesh.indices[3 * f + 2]}];
  const float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const float e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
}

//! Area-weighted unit normals per vertex (readers weld split vertices, so seams stay smooth).
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
    const float len = std::sqrt(normals[v] * normals[v] + normals[v + 1] * normals[v + 1] + normals[v + 2] * normals[v + 2]);
    if (len > 0.0f) {
      normals[v] /= len;
      normals[v + 1] /= len;
      normals[v + 2] /= len;
    }
  }
  return normals;
}

// === Patches and seams ===========================================================================

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

//! Line end points (centred positions, xyz) of every seam edge: mesh boundaries, edges between
//! different patches, and edges whose two faces disagree on the UVs.
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

// === Per-face colours ============================================================================

//! Distortion colours: log2 of each face's UV-to-3D area ratio relative to the mesh-wide ratio.
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

// === Matrices (column-major, as glLoadMatrixf wants) =============================================

using Mat4 = std::array<float, 16>;

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

// Rotation taking the chosen up axis to +y (column-major; each is a proper rotation, so the
// winding and the lighting stay right).
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

//! The next mipmap level: a 2x2 box filter (the last row/column repeats on odd sizes).
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
      const size_t a = at(2 * x, 2 * y), b = at(2 * x + 1, 2 * y), c = at(2 * x, 2 * y + 1), d = at(2 * x + 1, 2 * y + 1);
      const size_t out = (static_cast<size_t>(y) * static_cast<size_t>(dst.width) + static_cast<size_t>(x)) * ch;
      for (size_t k = 0; k < ch; ++k) {
        const int sum = src.pixels[a + k] + src.pixels[b + k] + src.pixels[c + k] + src.pixels[d + k];
        dst.pixels[out + k] = static_cast<uint8_t>((sum + 2) / 4);
      }
    }
  }
  return dst;
}

//! Uploads a repeating, trilinearly filtered texture. The mipmap chain is built on the CPU:
//! glGenerateMipmap would make llvmpipe compile a blit shader, which costs more than the filtering.
void upload_texture(const Image& image) {
  static constexpr std::array<GLenum, 4> kFormats = {GL_LUMINANCE, GL_LUMINANCE_ALPHA, GL_RGB, GL_RGBA};
  const GLenum format = kFormats[static_cast<size_t>(image.channels - 1)];
  GLuint id = 0;
  glGenTextures(1, &id);
  glBindTexture(GL_TEXTURE_2D, id);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  Image level_image;
  const Image* current = &image;
  for (GLint level = 0;; ++level) {
    glTexImage2D(GL_TEXTURE_2D, level, static_cast<GLint>(format), current->width, current->height, 0, format,
                 GL_UNSIGNED_BYTE, current->pixels.data());
    if (current->width == 1 && current->height == 1) break;
    level_image = half_size(*current);
    current = &level_image;
  }
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
  glEnable(GL_TEXTURE_2D);
}

// === Drawing =====================================================================================

//! Attribute pointers of one draw: positions and normals always, then either texture coordinates
//! or RGBA colours. Buffers are bound to GL_ARRAY_BUFFER one after the other.
struct VertexStreams {
  std::span<const float> positions;  // xyz, centred on the framing sphere
  std::span<const float> normals;    // xyz
  std::span<const float> texcoords;  // st, or empty
  std::span<const uint8_t> colors;   // rgba, or empty
};

void bind_streams(const VertexStreams& in, const std::array<GLuint, 4>& buffers) {
  const auto upload = [](GLuint buffer, const void* data, size_t bytes) {
    glBindBuffer(GL_ARRAY_BUFFER, buffer);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(bytes), data, GL_STREAM_DRAW);
  };
  glEnableClientState(GL_VERTEX_ARRAY);
  upload(buffers[0], in.positions.data(), in.positions.size_bytes());
  glVertexPointer(3, GL_FLOAT, 0, nullptr);
  glEnableClientState(GL_NORMAL_ARRAY);
  upload(buffers[1], in.normals.data(), in.normals.size_bytes());
  glNormalPointer(GL_FLOAT, 0, nullptr);
  if (!in.texcoords.empty()) {
    glEnableClientState(GL_TEXTURE_COORD_ARRAY);
    upload(buffers[2], in.texcoords.data(), in.texcoords.size_bytes());
    glTexCoordPointer(2, GL_FLOAT, 0, nullptr);
  }
  if (!in.colors.empty()) {
    glEnableClientState(GL_COLOR_ARRAY);
    upload(buffers[3], in.colors.data(), in.colors.size_bytes());
    glColorPointer(4, GL_UNSIGNED_BYTE, 0, nullptr);
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

void unbind_streams() {
  glDisableClientState(GL_VERTEX_ARRAY);
  glDisableClientState(GL_NORMAL_ARRAY);
  glDisableClientState(GL_TEXTURE_COORD_ARRAY);
  glDisableClientState(GL_COLOR_ARRAY);
}

//! Indexed drawing of a mesh split so that every vertex carries one key (a UV, or a patch id):
//! llvmpipe shades each split vertex about once instead of once per corner, which is most of the
//! cost on large meshes. `key` is #F*3 by 2 floats; `key_is_uv` says whether it is a texture
//! coordinate (else a patch id encoded as two exact floats, see draw_patch_surface).
void draw_split_surface(const Mesh& mesh, std::span<const float> key, bool key_is_uv,
                        std::span<const float> vertex_normal, const Framing& frame) {
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
  std::array<GLuint, 4> buffers{};
  GLuint element_buffer = 0;
  glGenBuffers(4, buffers.data());
  glGenBuffers(1, &element_buffer);
  bind_streams({positions, normals, texcoords, colors}, buffers);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, element_buffer);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(split.indices.size() * sizeof(uint32_t)),
               split.indices.data(), GL_STATIC_DRAW);
  // Batches keep every count within GLsizei.
  const size_t total = split.indices.size();
  for (size_t start = 0; start < total; start += 3 * kBatchFaces) {
    const size_t n = std::min(3 * kBatchFaces, total - start);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(n), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(start * sizeof(uint32_t)));
  }
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
  unbind_streams();
  glDeleteBuffers(1, &element_buffer);
  glDeleteBuffers(4, buffers.data());
}

//! Patch colours: vertices are split on (vertex, patch) so each patch keeps its own colour.
void draw_patch_surface(const Mesh& mesh, std::span<const uint32_t> patch, std::span<const float> vertex_normal,
                        const Framing& frame) {
  // A patch id as two floats that hold it exactly (24 + 8 bits), so splitting compares ids exactly.
  std::vector<float> key(2 * mesh.indices.size(), 0.0f);
  for (size_t c = 0; c < mesh.indices.size(); ++c) {
    const uint32_t id = patch.empty() ? 0 : patch[c / 3];
    key[2 * c] = static_cast<float>(id & 0xFFFFFFu);
    key[2 * c + 1] = static_cast<float>(id >> 24);
  }
  draw_split_surface(mesh, key, false, vertex_normal, frame);
}

//! Per-face colours (distortion): unindexed triangles, filled and drawn in batches so memory stays
//! bounded (108 bytes of arrays per face would otherwise be needed at once).
void draw_face_colored_surface(const Mesh& mesh, const std::vector<Rgb>& face_colors,
                               std::span<const float> vertex_normal, const Framing& frame) {
  const size_t faces = mesh.face_count();
  const size_t batch = std::min(faces, kBatchFaces);
  std::vector<float> pos(9 * batch), nor(9 * batch);
  std::vector<uint8_t> col(12 * batch);
  std::array<GLuint, 4> buffers{};
  glGenBuffers(4, buffers.data());
  for (size_t start = 0; start < faces; start += batch) {
    const size_t count = std::min(batch, faces - start);
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
    bind_streams({std::span<const float>(pos).first(9 * count), std::span<const float>(nor).first(9 * count), {},
                  std::span<const uint8_t>(col).first(12 * count)},
                 buffers);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(3 * count));
  }
  unbind_streams();
  glDeleteBuffers(4, buffers.data());
}

void draw_lines(const std::vector<float>& lines, float width) {
  if (lines.empty()) return;
  GLuint buffer = 0;
  glGenBuffers(1, &buffer);
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(lines.size() * sizeof(float)), lines.data(), GL_STATIC_DRAW);
  glEnableClientState(GL_VERTEX_ARRAY);
  glVertexPointer(3, GL_FLOAT, 0, nullptr);
  glLineWidth(width);
  glColor3ub(kSeamColor[0], kSeamColor[1], kSeamColor[2]);
  glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(lines.size() / 3));
  glDisableClientState(GL_VERTEX_ARRAY);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  glDeleteBuffers(1, &buffer);
}

//! Where the legend bar sits, in output pixels (y from the top).
struct LegendBox {
  int x = 0, y = 0, width = 0, height = 0, text_scale = 1;
};

LegendBox legend_box(int width, int height) {
  LegendBox box;
  box.text_scale = std::max(1, height / 300);
  box.width = width / 2;
  box.height = std::max(6, height / 40);
  box.x = (width - box.width) / 2;
  box.y = height - box.height - 7 * box.text_scale - std::max(8, height / 40);
  return box;
}

//! The colour bar of the distortion view, drawn in render-target pixels (`scale` = supersampling).
void draw_legend_bar(const LegendBox& box, int target_width, int target_height, int scale) {
  constexpr int kSteps = 64;
  const float x0 = static_cast<float>(box.x * scale);
  const float w = static_cast<float>(box.width * scale);
  // GL's y runs upwards.
  const float y_top = static_cast<float>(target_height - box.y * scale);
  const float y_bottom = y_top - static_cast<float>(box.height * scale);
  const float pad = static_cast<float>(scale * std::max(1, box.height / 6));
  std::vector<float> xy;
  std::vector<uint8_t> rgba;
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
  const size_t frame_vertices = xy.size() / 2;
  for (int i = 0; i <= kSteps; ++i) {
    const float t = static_cast<float>(i) / kSteps;
    const Rgb c = internal::heat_color(2.0f * t - 1.0f);
    vertex(x0 + t * w, y_bottom, c);
    vertex(x0 + t * w, y_top, c);
  }
  glMatrixMode(GL_PROJECTION);
  const Mat4 ortho = orthographic(target_width, target_height);
  glLoadMatrixf(ortho.data());
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_LIGHTING);
  glDisable(GL_TEXTURE_2D);
  glShadeModel(GL_SMOOTH);
  glEnableClientState(GL_VERTEX_ARRAY);
  glEnableClientState(GL_COLOR_ARRAY);
  glVertexPointer(2, GL_FLOAT, 0, xy.data());
  glColorPointer(4, GL_UNSIGNED_BYTE, 0, rgba.data());
  glDrawArrays(GL_TRIANGLE_STRIP, 0, static_cast<GLsizei>(frame_vertices));
  glDrawArrays(GL_TRIANGLE_STRIP, static_cast<GLint>(frame_vertices), static_cast<GLsizei>(2 * (kSteps + 1)));
  glDisableClientState(GL_COLOR_ARRAY);
  glDisableClientState(GL_VERTEX_ARRAY);
}

std::string ratio_label(double ratio) {
  std::array<char, 32> buf{};
  std::snprintf(buf.data(), buf.size(), "%.3gx", ratio);
  return buf.data();
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

//! Box-filters the RGBA render target (bottom row first) down by `scale` into an RGB image.
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

Status check_inputs(const Mesh& mesh, std::span<const float> corner_uv, std::span<const uint32_t> patch,
                    const Image* texture, const RenderOptions& o) {
  auto bad = [](const std::string& what) { return Status::error(ErrorCode::kInvalidArgument, "", what); };
  if (o.width < 16 || o.height < 16 || o.width > kMaxOutputSide || o.height > kMaxOutputSide) {
    return bad("preview size must be between 16 and " + std::to_string(kMaxOutputSide) + " pixels a side");
  }
  if (o.supersample < 1 || o.supersample > 4) return bad("supersample must be 1..4");
  if (!(o.fov_degrees >= 5.0f && o.fov_degrees <= 120.0f)) return bad("field of view must be 5..120 degrees");
  if (!(o.pitch_degrees >= -89.0f && o.pitch_degrees <= 89.0f)) return bad("pitch must be -89..89 degrees");
  if (!std::isfinite(o.yaw_degrees)) return bad("yaw must be finite");
  if (!(o.checker_squares > 0.0f && o.checker_squares < 1e6f)) return bad("checker squares must be positive");
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
  if (texture != nullptr && o.view == PreviewView::kTexture) {
    if (texture->channels < 1 || texture->channels > 4 || texture->width < 1 || texture->height < 1 ||
        texture->width > kMaxImageSide || texture->height > kMaxImageSide ||
        texture->pixels.size() != static_cast<size_t>(texture->width) * static_cast<size_t>(texture->height) *
                                      static_cast<size_t>(texture->channels)) {
      return Status::error(ErrorCode::kInvalidImage, "", "texture image is empty or inconsistent");
    }
  }
  return Status::ok();
}

}  // namespace

bool preview_view_from_name(std::string_view name, PreviewView& view) {
  for (const PreviewView v : {PreviewView::kTexture, PreviewView::kPatches, PreviewView::kDistortion, PreviewView::kChecker}) {
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
  }
  return "texture";
}

Status render_preview(const Mesh& mesh, std::span<const float> corner_uv, std::span<const uint32_t> patch,
                      const Image* texture, const RenderOptions& options, Image& out) {
  out = Image{};
  TAILOR_RETURN_IF_ERROR(check_inputs(mesh, corner_uv, patch, texture, options));
  try {
    // Supersampling is reduced rather than refused when the target would get too large.
    int scale = options.supersample;
    while (scale > 1 && (options.width * scale > kMaxRenderSide || options.height * scale > kMaxRenderSide)) --scale;
    const int target_width = options.width * scale;
    const int target_height = options.height * scale;

    const Framing frame = frame_mesh(mesh);
    const std::vector<float> normals = vertex_normals(mesh);
    std::vector<Rgb> face_colors;
    std::vector<float> lines;
    std::vector<uint32_t> derived;
    std::span<const uint32_t> patch_ids = patch;
    const bool textured = options.view == PreviewView::kTexture || options.view == PreviewView::kChecker;
    if (options.view == PreviewView::kPatches) {
      const bool need_topology = options.draw_seams || (patch.empty() && !corner_uv.empty());
      Topology topology;
      if (need_topology) topology = build_topology(mesh);
      if (patch.empty() && !corner_uv.empty()) {
        derive_patches(mesh, topology, corner_uv, derived);
        patch_ids = derived;
      }
      if (options.draw_seams) lines = seam_lines(mesh, topology, corner_uv, patch_ids, frame);
    } else if (options.view == PreviewView::kDistortion) {
      face_colors = distortion_colors(mesh, corner_uv, options.distortion_range);
    }

    OffscreenContext context;
    if (!context.create(target_width, target_height)) {
      return Status::error(ErrorCode::kUnsupported, "", "cannot create an off-screen OpenGL context (OSMesa)");
    }
    GLint max_texture = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture);
    const bool use_image = options.view == PreviewView::kTexture && texture != nullptr;
    if (use_image && (texture->width > max_texture || texture->height > max_texture)) {
      return Status::error(ErrorCode::kUnsupported, "", "texture larger than the renderer allows",
                           std::to_string(max_texture) + " pixels a side");
    }

    // The distortion view keeps a band at the bottom for its legend, so the mesh never hides it.
    const LegendBox box = legend_box(options.width, options.height);
    const int band = options.view == PreviewView::kDistortion ? options.height - box.y + box.height : 0;
    glViewport(0, band * scale, target_width, target_height - band * scale);
    glClearColor(kBackground[0] / 255.0f, kBackground[1] / 255.0f, kBackground[2] / 255.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);

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
    glMatrixMode(GL_PROJECTION);
    const Mat4 projection = perspective(fovy, aspect, near_plane, far_plane);
    glLoadMatrixf(projection.data());

    // Light fixed in eye space (up-left of the camera) before the view matrix is loaded.
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    const std::array<GLfloat, 4> light_dir = {-0.35f, 0.55f, 0.76f, 0.0f};
    const std::array<GLfloat, 4> diffuse = {0.72f, 0.72f, 0.72f, 1.0f};
    const std::array<GLfloat, 4> ambient = {0.0f, 0.0f, 0.0f, 1.0f};
    const std::array<GLfloat, 4> scene_ambient = {0.36f, 0.36f, 0.36f, 1.0f};
    glLightfv(GL_LIGHT0, GL_POSITION, light_dir.data());
    glLightfv(GL_LIGHT0, GL_DIFFUSE, diffuse.data());
    glLightfv(GL_LIGHT0, GL_AMBIENT, ambient.data());
    glLightModelfv(GL_LIGHT_MODEL_AMBIENT, scene_ambient.data());
    glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_TRUE);  // open meshes show their inside lit too
    glEnable(GL_LIGHTING);
    glEnable(GL_LIGHT0);
    glEnable(GL_COLOR_MATERIAL);
    glColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
    glShadeModel(GL_SMOOTH);
    const Mat4 view = look_at(eye);
    glLoadMatrixf(view.data());
    const Mat4 turn = up_rotation(options.up);
    glMultMatrixf(turn.data());

    glColor4ub(255, 255, 255, 255);
    if (textured) {
      if (use_image) {
        upload_texture(*texture);
      } else {
        const bool checker = options.view == PreviewView::kChecker;
        upload_texture(checker ? checker_image(kCheckerDark, kCheckerLight) : checker_image(kNeutralDark, kNeutralLight));
        // The generated image holds 2x2 squares.
        glMatrixMode(GL_TEXTURE);
        glLoadIdentity();
        glScalef(options.checker_squares / 2.0f, options.checker_squares / 2.0f, 1.0f);
        glMatrixMode(GL_MODELVIEW);
      }
    }
    // Seams are drawn on top of the faces: push the faces back a little.
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 1.0f);

    if (textured) draw_split_surface(mesh, corner_uv, true, normals, frame);
    else if (options.view == PreviewView::kPatches) draw_patch_surface(mesh, patch_ids, normals, frame);
    else draw_face_colored_surface(mesh, face_colors, normals, frame);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDisable(GL_LIGHTING);
    glDisable(GL_TEXTURE_2D);
    draw_lines(lines, 1.25f * static_cast<float>(scale));

    glViewport(0, 0, target_width, target_height);
    if (options.view == PreviewView::kDistortion) draw_legend_bar(box, target_width, target_height, scale);
    glFinish();
    if (glGetError() == GL_OUT_OF_MEMORY) {
      return Status::error(ErrorCode::kUnsupported, "", "the renderer ran out of memory");
    }

    out.width = options.width;
    out.height = options.height;
    out.channels = 3;
    out.pixels.assign(static_cast<size_t>(out.width) * static_cast<size_t>(out.height) * 3, 0);
    resolve(context.pixels(), target_width, scale, out);
    if (options.view == PreviewView::kDistortion) draw_legend_text(box, options.distortion_range, out);
    return Status::ok();
  } catch (const std::bad_alloc&) {
    out = Image{};
    return Status::error(ErrorCode::kLimit, "", "out of memory while rendering the preview");
  } catch (const std::exception& e) {
    out = Image{};
    return Status::error(ErrorCode::kUnsupported, "", std::string("rendering failed: ") + e.what());
  }
}

}  // namespace tailor
