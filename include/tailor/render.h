// tailor: headless preview pictures of a UV-mapped mesh.
//
// Renders the mesh on the CPU with Mesa's off-screen OpenGL (OSMesa, llvmpipe): a 3/4 view from
// above with one directional light plus ambient, textured with GL_REPEAT and mipmaps (the texture
// view lit per pixel, with a material's normal and occlusion maps: PreviewMaterial). Views:
//   kTexture     the texture (or, when none is given, a neutral grey checker) on the surface;
//   kPatches     each patch in its own colour, seams (edges whose two faces disagree on patch or
//                UV) drawn as dark lines;
//   kDistortion  per-face area stretch r_f / R (UV area over 3D area, divided by the mesh-wide
//                ratio R = sum a / sum A) as a heat map of log2(r_f / R): blue = shrunk,
//                white = ideal, red = enlarged, with a colour-bar legend along the bottom;
//   kChecker     a black/white checker texture, the classic way to judge stretch and shear.
//
// libOSMesa (Debian's libosmesa6) is loaded at the first call, not linked: a program that links
// tailor::render and never draws does not carry Mesa's LLVM (~50 MB resident).
// Thread safety: every call creates and destroys its own OSMesa context (OSMesa contexts are not
// safe to share across calls); calls from several threads at once are not supported.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "tailor/api.h"
#include "tailor/image.h"
#include "tailor/mesh.h"
#include "tailor/option_doc.h"
#include "tailor/status.h"

namespace tailor {

//! What the preview colours the surface with (see the top of this file).
enum class PreviewView {
  kTexture,     //!< the texture (or a neutral checker)
  kPatches,     //!< a colour per patch, seams drawn
  kDistortion,  //!< area-stretch heat map with a legend
  kChecker,     //!< a black and white checker per texture repeat
  kSeams,       //!< grey surface; visible seams red, invisible ones green (seam_gap_px in metrics.h)
};

//! Parses "texture", "patches", "distortion" or "checker"; returns false for anything else.
TAILOR_API bool preview_view_from_name(std::string_view name, PreviewView& view);

//! The lowercase name of a view ("texture", ...).
TAILOR_API const char* preview_view_name(PreviewView view);

//! Which mesh axis points up in the picture (scans are often z-up; glTF is y-up).
enum class UpAxis { kPosY, kPosZ, kPosX, kNegY, kNegZ, kNegX };

//! Parses "y", "z", "x", "-y", "-z" or "-x" (also with a leading '+'); false for anything else.
TAILOR_API bool up_axis_from_name(std::string_view name, UpAxis& up);

//! The name of an up axis, as up_axis_from_name reads it: "y", "z", "x", "-y", "-z" or "-x".
inline const char* up_axis_name(UpAxis up) {
  switch (up) {
    case UpAxis::kPosY: return "y";
    case UpAxis::kPosZ: return "z";
    case UpAxis::kPosX: return "x";
    case UpAxis::kNegY: return "-y";
    case UpAxis::kNegZ: return "-z";
    case UpAxis::kNegX: return "-x";
  }
  return "y";
}

struct RenderOptions {
  int width = 1024;                          //!< output width in pixels, 16..8192
  int height = 768;                          //!< output height in pixels, 16..8192
  PreviewView view = PreviewView::kTexture;  //!< what the surface shows
  UpAxis up = UpAxis::kPosY;                 //!< mesh axis shown pointing up (the mesh is turned, not the light)
  float yaw_degrees = 35.0f;                 //!< camera azimuth around the up axis (for +y: from +z towards +x)
  float pitch_degrees = 25.0f;               //!< camera elevation above the horizontal plane, -89..89
  float fov_degrees = 35.0f;                 //!< vertical field of view, 5..120
  float checker_squares = 8.0f;              //!< kChecker (and the fallback texture): squares per texture repeat, > 0
  float distortion_range = 2.0f;             //!< kDistortion: |log2(r_f / R)| mapped to full colour, > 0 (2 = 4x)
  bool draw_seams = true;                    //!< kPatches: draw seam edges as lines
  int seam_texture_px = 0;                   //!< kSeams: texture size in pixels a seam's gap is measured in (a
                                             //!< gap under 1 px is invisible); 0 = the texture's width and
                                             //!< height, or 512 without a texture
  uint32_t seam_symmetry = 1;                //!< kSeams: 4 = a quarter turn across a seam is invisible too
  int supersample = 2;                       //!< render at this multiple of the size and box-filter down, 1..4
};

//! Flags and help of the RenderOptions a user sets (option_doc.h); `tailor map` names --up
//! --preview-up.
inline constexpr OptionDoc kRenderOptionDocs[] = {
    {"view", "--view",
     "texture, patches (a colour per patch, seams drawn), distortion (area-stretch heat map with legend), "
     "checker, or seams (visible seams red, invisible ones green: where the texture continues across the cut)"},
    {"width", "--size", "picture size WIDTHxHEIGHT"},
    {"up", "--up", "mesh axis that points up in the picture: y (glTF), z (most scans), x, -x, -y, -z"},
    {"yaw_degrees", "--yaw", "camera azimuth in degrees around the up axis"},
    {"pitch_degrees", "--pitch", "camera elevation in degrees"},
    {"checker_squares", "--checker", "checker squares per texture repeat"},
    {"seam_symmetry", "--symmetry",
     "seams view: 1, or 4 for a map from 'tailor map --symmetry 4' (a seam whose sides differ by a quarter turn "
     "plus whole repeats is drawn invisible, green; needs a square texture)"},
};

//! What the texture view shades with besides the base colour: glTF's material maps, all optional.
//! With a normal map the surface is lit per pixel with the map's normal in the tangent frame
//! (t, b = w * n x t, n), as glTF, three.js and `tailor view` do; occlusion scales the ambient
//! light only (glTF: indirect light). Roughness and metallic have no part in this light model
//! (one directional light, diffuse, plus ambient) and are not read.
struct PreviewMaterial {
  const Image* normal = nullptr;           //!< tangent-space normal map, glTF (OpenGL) convention: +Y up the image
  const Image* occlusion = nullptr;        //!< ambient occlusion in the R channel (glTF occlusionTexture)
  std::span<const float> corner_tangents;  //!< #F*3 by 4 (unit xyz, w = +-1), glTF TANGENT per corner;
                                           //!< empty: corner_tangents (export.h) of the UVs
  bool empty() const { return normal == nullptr && occlusion == nullptr; }
};

//! Renders a preview picture of `mesh`.
//!   mesh:      a valid mesh (after finalize_mesh: indices < #V, finite positions), at least one face.
//!   corner_uv: #F*3 by 2 texture coordinates per corner in texture repeats (1.0 = one texture
//!              width), v up as in glTF-flipped/OBJ; may be empty for kPatches (one colour, no seams
//!              from UVs) but is required for kTexture, kDistortion and kChecker.
//!   patch:     #F patch ids; may be empty: then patches are derived from the UVs (faces joined
//!              across edges whose two corners have identical UVs on both sides), or one colour
//!              when corner_uv is empty too.
//!   texture:   RGB/RGBA/grey 8-bit image used by kTexture; may be null: then a neutral checker.
//!   out:       on success an RGB image (3 channels, image.h layout, top row first) of
//!              options.width by options.height pixels; left empty on failure.
//! Fails with kInvalidArgument for bad options or array sizes, kInvalidMesh for an empty mesh or
//! out-of-range indices, kUnsupported when no OpenGL context can be created (libOSMesa missing:
//! the message names it and its package; or out of memory). Cost: O(F) to build vertex arrays
//! plus the rasterisation; about a second for 1 M faces at 1024x768 on two cores. Never prints,
//! never throws.
TAILOR_API Status render_preview(const Mesh& mesh, std::span<const float> corner_uv, std::span<const uint32_t> patch,
                                 const Image* texture, const RenderOptions& options, Image& out);

//! The same with a material's other maps (PreviewMaterial), used by the texture view only. Every
//! texture view is lit per pixel by a GLSL shader (with or without a material, so that a flat
//! normal map changes nothing; an OpenGL without GLSL falls back to per-vertex light when no map is
//! given, and fails with kUnsupported when one is); the maps share the texture's UVs. Also fails
//! with kInvalidImage for an inconsistent map and kInvalidArgument for tangents of the wrong size
//! or not finite.
TAILOR_API Status render_preview(const Mesh& mesh, std::span<const float> corner_uv, std::span<const uint32_t> patch,
                                 const Image* texture, const PreviewMaterial& material, const RenderOptions& options,
                                 Image& out);

}  // namespace tailor
