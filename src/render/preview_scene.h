// What a preview picture shows, prepared on the CPU (osmesa_backend.cpp draws it with OpenGL): the
// checks of the inputs, the scene (framing, vertex normals, the colours of each view, seam lines),
// the camera's matrices, the vertex arrays handed to GL, the generated textures, and after the
// read-back the box filter and the legend's text. No GL here.
//
// Patches and per-face area stretch come from metrics.h (one definition for eval and the
// pictures). Text of the legend is stamped on the CPU after read-back.
//
// The checker view is the classic stretch test of parameterisation papers, e.g. Sander, Snyder,
// Gortler, Hoppe, "Texture mapping progressive meshes", SIGGRAPH 2001; the heat map uses the end
// points of Moreland, "Diverging color maps for scientific visualization", ISVC 2009.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "render/preview_colors.h"
#include "tailor/export.h"
#include "tailor/image.h"
#include "tailor/mesh.h"
#include "tailor/render.h"
#include "tailor/status.h"
#include "tailor/topology.h"

namespace tailor::internal {

inline constexpr Rgb kBackground = {236, 238, 242};
inline constexpr Rgb kSeamColor = {20, 20, 28};
inline constexpr Rgb kVisibleSeamColor = {225, 30, 30};    // seams view: the texture breaks here
inline constexpr Rgb kInvisibleSeamColor = {20, 170, 60};  // seams view: a cut the texture continues across
inline constexpr Rgb kSeamsSurface = {200, 200, 200};
inline constexpr Rgb kLegendInk = {30, 30, 36};
// Checker tiles: light/dark grey for the neutral stand-in texture, near black/white for the checker view.
inline constexpr Rgb kNeutralDark = {150, 150, 150};
inline constexpr Rgb kNeutralLight = {205, 205, 205};
inline constexpr Rgb kCheckerDark = {35, 35, 40};
inline constexpr Rgb kCheckerLight = {240, 240, 240};
inline constexpr int kCheckerTexels = 64;  // per checker square in the generated texture (2x2 squares)

//! Sizes, angles and array lengths of a render_preview call (the public entry point checks them
//! before anything else).
Status check_inputs(const Mesh& mesh, std::span<const float> corner_uv, std::span<const uint32_t> patch,
                    const Image* texture, const PreviewMaterial& material, const RenderOptions& o);

// === Geometry set-up =============================================================================

struct Framing {
  std::array<double, 3> center{};
  double radius = 1.0;
};

//! Centre of the bounding box and the radius of the sphere around it holding every used vertex.
Framing frame_mesh(const Mesh& mesh);

//! Area-weighted unit normals per vertex (readers weld split vertices, so seams stay smooth).
std::vector<float> vertex_normals(const Mesh& mesh);

//! Line end points (centred positions, xyz) of every seam edge: mesh boundaries, edges between
//! different patches, and edges whose two faces disagree on the UVs.
std::vector<float> seam_lines(const Mesh& mesh, const Topology& topology, std::span<const float> uv,
                              std::span<const uint32_t> patch, const Framing& frame);

//! Distortion colours: log2 of each face's UV-to-3D area ratio relative to the mesh-wide ratio.
std::vector<Rgb> distortion_colors(const Mesh& mesh, std::span<const float> uv, float range);

//! What the drawing needs besides the mesh: its framing and vertex normals, and by view the face
//! colours (distortion), the patch ids (the given ones, or derived from the UVs when none are
//! given) and the seam lines (patches). patch_ids may point into derived: not copyable.
struct PreviewScene {
  PreviewScene() = default;
  PreviewScene(const PreviewScene&) = delete;
  PreviewScene& operator=(const PreviewScene&) = delete;

  Framing frame;
  std::vector<float> normals;
  std::vector<Rgb> face_colors;
  std::vector<float> lines;            // seam lines (kPatches), visible seams (kSeams)
  std::vector<float> invisible_lines;  // kSeams: invisible seams
  int texture_width = 512;             // kSeams: the texture's size, when one is given
  int texture_height = 512;
  std::vector<uint32_t> derived;
  std::span<const uint32_t> patch_ids;
};

void prepare_scene(const Mesh& mesh, std::span<const float> corner_uv, std::span<const uint32_t> patch,
                   const RenderOptions& options, PreviewScene& scene);

// === Matrices (column-major, as glLoadMatrixf wants) =============================================

using Mat4 = std::array<float, 16>;

Mat4 perspective(double fovy_radians, double aspect, double near_plane, double far_plane);
Mat4 look_at(const std::array<double, 3>& eye);
// Rotation taking the chosen up axis to +y (column-major; each is a proper rotation, so the
// winding and the lighting stay right).
Mat4 up_rotation(UpAxis up);
Mat4 orthographic(double width, double height);

//! The camera's matrices: projection, view (looking at the framing sphere's centre) and the turn
//! of the mesh's up axis to +y, for a viewport `band` output pixels shorter than the picture.
struct Camera {
  Mat4 projection{}, view{}, turn{};
};

Camera place_camera(const Framing& frame, const RenderOptions& options, int band);

// === Textures ====================================================================================

Image checker_image(Rgb dark, Rgb light);

//! The next mipmap level: a 2x2 box filter (the last row/column repeats on odd sizes).
Image half_size(const Image& src);

// === Vertex arrays ===============================================================================

//! A mesh split so that every vertex carries one key (a UV, or a patch id), with its vertex
//! arrays (positions centred on the framing sphere, normals, and texture coordinates or RGBA
//! colours): llvmpipe shades each split vertex about once instead of once per corner, which is
//! most of the cost on large meshes. The split's indices are the triangles to draw.
struct SplitSurface {
  SplitMesh split;
  std::vector<float> positions, normals, texcoords;
  std::vector<float> tangents;  // xyzw per split vertex: the sum of its corners' tangents, w their majority sign
  std::vector<uint8_t> colors;
};

//! `key` is #F*3 by 2 floats; `key_is_uv` says whether it is a texture coordinate (else a patch
//! id encoded as two exact floats, see patch_keys). corner_tangent: empty, or #F*3 by 4.
SplitSurface split_surface(const Mesh& mesh, std::span<const float> key, bool key_is_uv,
                           std::span<const float> vertex_normal, const Framing& frame,
                           std::span<const float> corner_tangent = {});

//! The split key of each corner for the patch colours (vertices split on (vertex, patch), so each
//! patch keeps its own colour): its face's patch id.
std::vector<float> patch_keys(const Mesh& mesh, std::span<const uint32_t> patch);

//! Per-face colours (distortion), unindexed: the arrays of faces start .. start + count - 1
//! (pos and nor 9 floats a face, col 12 bytes).
void fill_face_colored_batch(const Mesh& mesh, const std::vector<Rgb>& face_colors,
                             std::span<const float> vertex_normal, const Framing& frame, size_t start, size_t count,
                             std::vector<float>& pos, std::vector<float>& nor, std::vector<uint8_t>& col);

// === Legend ======================================================================================

//! Where the legend bar sits, in output pixels (y from the top).
struct LegendBox {
  int x = 0, y = 0, width = 0, height = 0, text_scale = 1;
};

LegendBox legend_box(int width, int height);

//! The colour bar of the distortion view in render-target pixels (`scale` = supersampling):
//! xy and rgba per vertex, the frame's frame_vertices first, then the bar's.
struct LegendBar {
  std::vector<float> xy;
  std::vector<uint8_t> rgba;
  size_t frame_vertices = 0;
};

LegendBar legend_bar(const LegendBox& box, int target_height, int scale);

void draw_legend_text(const LegendBox& box, float range, Image& out);

// === Read-back ===================================================================================

//! Box-filters the RGBA render target (bottom row first) down by `scale` into an RGB image.
void resolve(const std::vector<uint8_t>& rgba, int target_width, int scale, Image& out);

}  // namespace tailor::internal
