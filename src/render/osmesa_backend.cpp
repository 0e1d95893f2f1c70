// Headless preview pictures with Mesa's off-screen OpenGL (OSMesa on llvmpipe).
//
// The mesh is drawn as unindexed triangles (UVs and colours live per corner) from vertex buffer
// objects filled in batches, so memory stays bounded for any face count and no immediate mode is
// used.
//
// What is drawn is prepared on the CPU by preview_scene.h (framing, colours, camera, vertex
// arrays); this file holds everything that talks to GL: the context, the texture upload, the
// buffers and draw calls, and render_preview, which runs the whole picture.
#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "render/gl_api.h"
#include "render/preview_scene.h"
#include "tailor/export.h"
#include "tailor/image.h"
#include "tailor/render.h"

namespace tailor {

// What is prepared on the CPU (preview_scene.h).
using internal::Camera;
using internal::check_inputs;
using internal::checker_image;
using internal::draw_legend_text;
using internal::fill_face_colored_batch;
using internal::Framing;
using internal::gl;
using internal::half_size;
using internal::kBackground;
using internal::kCheckerDark;
using internal::kCheckerLight;
using internal::kNeutralDark;
using internal::kNeutralLight;
using internal::kSeamColor;
using internal::legend_bar;
using internal::legend_box;
using internal::LegendBar;
using internal::LegendBox;
using internal::Mat4;
using internal::orthographic;
using internal::patch_keys;
using internal::place_camera;
using internal::prepare_scene;
using internal::PreviewScene;
using internal::resolve;
using internal::Rgb;
using internal::split_surface;
using internal::SplitSurface;

namespace {

// Faces per vertex-buffer batch: 3 corners x (3+3 floats + 2 floats + 4 bytes) = 108 bytes a
// face, so ~28 MB of arrays at a time, few enough draw calls that batching costs nothing.
constexpr size_t kBatchFaces = size_t{1} << 18;
// Largest render target side after supersampling (llvmpipe allows 16384; memory is the limit).
constexpr int kMaxRenderSide = 8192;

// === OSMesa context, created and destroyed per call =============================================

//! Owns the context of one render. The destructor unbinds it before destroying it, so that no
//! freed context stays current on the thread (a later GL call or OSMesaGetCurrentContext would
//! reach it). Objects made in the context (textures, buffers) are deleted by their owners before
//! this runs. Mesa 22.3 still keeps the ~160-byte framebuffer of each OSMesaMakeCurrent: see
//! tests/lsan.supp.
class OffscreenContext {
 public:
  OffscreenContext() = default;
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;
  ~OffscreenContext() {
    if (context_ == nullptr) return;
    if (gl().OSMesaGetCurrentContext() == context_) gl().OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
    gl().OSMesaDestroyContext(context_);
  }

  bool create(int width, int height) {
    context_ = gl().OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
    if (context_ == nullptr) return false;
    buffer_.assign(static_cast<size_t>(width) * static_cast<size_t>(height) * 4, 0);
    return gl().OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width, height) == GL_TRUE;
  }

  //! RGBA, bottom row first (OSMesa's default).
  const std::vector<uint8_t>& pixels() const { return buffer_; }

 private:
  OSMesaContext context_ = nullptr;
  std::vector<uint8_t> buffer_;
};

// === Textures ====================================================================================

//! The texture of one render, deleted when it goes out of scope (before the context: it is
//! declared after it).
class Texture {
 public:
  Texture() = default;
  Texture(const Texture&) = delete;
  Texture& operator=(const Texture&) = delete;
  ~Texture() {
    if (id_ != 0) gl().glDeleteTextures(1, &id_);
  }
  GLuint make() {
    if (id_ == 0) gl().glGenTextures(1, &id_);
    return id_;
  }

 private:
  GLuint id_ = 0;
};

//! Uploads a repeating, trilinearly filtered texture into `texture`. The mipmap chain is built on
//! the CPU: glGenerateMipmap would make llvmpipe compile a blit shader, which costs more than the
//! filtering.
void upload_texture(const Image& image, Texture& texture) {
  static constexpr std::array<GLenum, 4> kFormats = {GL_LUMINANCE, GL_LUMINANCE_ALPHA, GL_RGB, GL_RGBA};
  const GLenum format = kFormats[static_cast<size_t>(image.channels - 1)];
  gl().glBindTexture(GL_TEXTURE_2D, texture.make());
  gl().glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  Image level_image;
  const Image* current = &image;
  for (GLint level = 0;; ++level) {
    gl().glTexImage2D(GL_TEXTURE_2D, level, static_cast<GLint>(format), current->width, current->height, 0, format,
                      GL_UNSIGNED_BYTE, current->pixels.data());
    if (current->width == 1 && current->height == 1) break;
    level_image = half_size(*current);
    current = &level_image;
  }
  gl().glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  gl().glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  gl().glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  gl().glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  gl().glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
  gl().glEnable(GL_TEXTURE_2D);
}

// === The texture view's shader ===================================================================

// The vertex attribute the tangents go to (0 is gl_Vertex in a compatibility context).
constexpr GLuint kTangentAttribute = 1;

// Per-pixel light, the viewer's (web/surface_material.js) with the same constants as the
// fixed-function light of the other views: ambient 0.36 (times the occlusion map) plus 0.72 times
// the diffuse term of one directional light fixed in eye space; two-sided. A normal map turns the
// interpolated normal by the tangent frame (t projected into the tangent plane, b = w * n x t),
// glTF's convention; a tangent of zero length leaves the normal as it is.
constexpr const char* kVertexShader = R"(#version 120
attribute vec4 tangent;
varying vec3 v_normal;
varying vec4 v_tangent;
varying vec2 v_uv;
void main() {
  v_normal = gl_NormalMatrix * gl_Normal;
  v_tangent = vec4(mat3(gl_ModelViewMatrix) * tangent.xyz, tangent.w);
  v_uv = gl_MultiTexCoord0.st;
  gl_Position = ftransform();
}
)";

constexpr const char* kFragmentShader = R"(#version 120
uniform sampler2D base_map;
uniform sampler2D normal_map;
uniform sampler2D occlusion_map;
uniform bool has_normal;
uniform bool has_occlusion;
uniform vec3 light_dir;
varying vec3 v_normal;
varying vec4 v_tangent;
varying vec2 v_uv;
void main() {
  vec3 n = normalize(v_normal);
  if (has_normal) {
    vec3 t = v_tangent.xyz - n * dot(n, v_tangent.xyz);
    if (dot(t, t) > 1e-12) {
      t = normalize(t);
      vec3 b = cross(n, t) * (v_tangent.w < 0.0 ? -1.0 : 1.0);
      vec3 m = texture2D(normal_map, v_uv).xyz * 2.0 - 1.0;
      n = normalize(t * m.x + b * m.y + n * m.z);
    }
  }
  if (!gl_FrontFacing) n = -n;
  float ambient = has_occlusion ? 0.36 * texture2D(occlusion_map, v_uv).r : 0.36;
  float light = ambient + 0.72 * max(dot(n, light_dir), 0.0);
  vec3 base = texture2D(base_map, (gl_TextureMatrix[0] * vec4(v_uv, 0.0, 1.0)).st).rgb;
  gl_FragColor = vec4(min(base * light, vec3(1.0)), 1.0);
}
)";

//! The linked program of the texture view, deleted when it goes out of scope (before the context).
class ShaderProgram {
 public:
  ShaderProgram() = default;
  ShaderProgram(const ShaderProgram&) = delete;
  ShaderProgram& operator=(const ShaderProgram&) = delete;
  ~ShaderProgram() {
    if (program_ != 0) gl().glDeleteProgram(program_);
  }

  //! Compiles and links; false (with the compiler's first line in `log`) when GLSL is missing.
  bool build(std::string& log) {
    program_ = gl().glCreateProgram();
    if (program_ == 0) return fail("no GLSL", log);
    for (const auto& [type, source] :
         {std::pair{GL_VERTEX_SHADER, kVertexShader}, {GL_FRAGMENT_SHADER, kFragmentShader}}) {
      const GLuint shader = gl().glCreateShader(type);
      gl().glShaderSource(shader, 1, &source, nullptr);
      gl().glCompileShader(shader);
      GLint ok = GL_FALSE;
      gl().glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
      if (ok != GL_TRUE) {
        std::array<char, 256> text{};
        gl().glGetShaderInfoLog(shader, static_cast<GLsizei>(text.size()), nullptr, text.data());
        gl().glDeleteShader(shader);
        return fail(text.data(), log);
      }
      gl().glAttachShader(program_, shader);
      gl().glDeleteShader(shader);  // freed with the program
    }
    gl().glBindAttribLocation(program_, kTangentAttribute, "tangent");
    gl().glLinkProgram(program_);
    GLint ok = GL_FALSE;
    gl().glGetProgramiv(program_, GL_LINK_STATUS, &ok);
    return ok == GL_TRUE || fail("link failed", log);
  }

  GLint uniform(const char* name) const { return gl().glGetUniformLocation(program_, name); }
  GLuint id() const { return program_; }

 private:
  static bool fail(const std::string& what, std::string& log) {
    log = what.substr(0, what.find('\n'));
    return false;
  }
  GLuint program_ = 0;
};

// === Drawing =====================================================================================

//! Attribute pointers of one draw: positions and normals always, then either texture coordinates
//! or RGBA colours, and tangents for the texture view's shader. Buffers are bound to
//! GL_ARRAY_BUFFER one after the other.
struct VertexStreams {
  std::span<const float> positions;  // xyz, centred on the framing sphere
  std::span<const float> normals;    // xyz
  std::span<const float> texcoords;  // st, or empty
  std::span<const uint8_t> colors;   // rgba, or empty
  std::span<const float> tangents;   // xyzw, or empty
};

void bind_streams(const VertexStreams& in, const std::array<GLuint, 5>& buffers) {
  const auto upload = [](GLuint buffer, const void* data, size_t bytes) {
    gl().glBindBuffer(GL_ARRAY_BUFFER, buffer);
    gl().glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(bytes), data, GL_STREAM_DRAW);
  };
  gl().glEnableClientState(GL_VERTEX_ARRAY);
  upload(buffers[0], in.positions.data(), in.positions.size_bytes());
  gl().glVertexPointer(3, GL_FLOAT, 0, nullptr);
  gl().glEnableClientState(GL_NORMAL_ARRAY);
  upload(buffers[1], in.normals.data(), in.normals.size_bytes());
  gl().glNormalPointer(GL_FLOAT, 0, nullptr);
  if (!in.texcoords.empty()) {
    gl().glEnableClientState(GL_TEXTURE_COORD_ARRAY);
    upload(buffers[2], in.texcoords.data(), in.texcoords.size_bytes());
    gl().glTexCoordPointer(2, GL_FLOAT, 0, nullptr);
  }
  if (!in.colors.empty()) {
    gl().glEnableClientState(GL_COLOR_ARRAY);
    upload(buffers[3], in.colors.data(), in.colors.size_bytes());
    gl().glColorPointer(4, GL_UNSIGNED_BYTE, 0, nullptr);
  }
  if (!in.tangents.empty()) {
    gl().glEnableVertexAttribArray(kTangentAttribute);
    upload(buffers[4], in.tangents.data(), in.tangents.size_bytes());
    gl().glVertexAttribPointer(kTangentAttribute, 4, GL_FLOAT, GL_FALSE, 0, nullptr);
  } else {
    gl().glVertexAttrib4f(kTangentAttribute, 0.0f, 0.0f, 0.0f, 1.0f);
  }
  gl().glBindBuffer(GL_ARRAY_BUFFER, 0);
}

void unbind_streams() {
  gl().glDisableClientState(GL_VERTEX_ARRAY);
  gl().glDisableClientState(GL_NORMAL_ARRAY);
  gl().glDisableClientState(GL_TEXTURE_COORD_ARRAY);
  gl().glDisableClientState(GL_COLOR_ARRAY);
  gl().glDisableVertexAttribArray(kTangentAttribute);
}

//! Indexed drawing of a mesh split so that every vertex carries one key (a UV, or a patch id):
//! llvmpipe shades each split vertex about once instead of once per corner, which is most of the
//! cost on large meshes. `key` is #F*3 by 2 floats; `key_is_uv` says whether it is a texture
//! coordinate (else a patch id encoded as two exact floats, see draw_patch_surface).
void draw_split_surface(const Mesh& mesh, std::span<const float> key, bool key_is_uv,
                        std::span<const float> vertex_normal, const Framing& frame,
                        std::span<const float> corner_tangent = {}) {
  const SplitSurface surface = split_surface(mesh, key, key_is_uv, vertex_normal, frame, corner_tangent);
  const SplitMesh& split = surface.split;
  std::array<GLuint, 5> buffers{};
  GLuint element_buffer = 0;
  gl().glGenBuffers(5, buffers.data());
  gl().glGenBuffers(1, &element_buffer);
  bind_streams({surface.positions, surface.normals, surface.texcoords, surface.colors, surface.tangents}, buffers);
  gl().glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, element_buffer);
  gl().glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(split.indices.size() * sizeof(uint32_t)),
                    split.indices.data(), GL_STATIC_DRAW);
  // Batches keep every count within GLsizei.
  const size_t total = split.indices.size();
  for (size_t start = 0; start < total; start += 3 * kBatchFaces) {
    const size_t n = std::min(3 * kBatchFaces, total - start);
    gl().glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(n), GL_UNSIGNED_INT,
                        reinterpret_cast<const void*>(start * sizeof(uint32_t)));
  }
  gl().glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
  unbind_streams();
  gl().glDeleteBuffers(1, &element_buffer);
  gl().glDeleteBuffers(5, buffers.data());
}

//! Patch colours: vertices are split on (vertex, patch) so each patch keeps its own colour.
void draw_patch_surface(const Mesh& mesh, std::span<const uint32_t> patch, std::span<const float> vertex_normal,
                        const Framing& frame) {
  const std::vector<float> key = patch_keys(mesh, patch);
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
  std::array<GLuint, 5> buffers{};
  gl().glGenBuffers(5, buffers.data());
  for (size_t start = 0; start < faces; start += batch) {
    const size_t count = std::min(batch, faces - start);
    fill_face_colored_batch(mesh, face_colors, vertex_normal, frame, start, count, pos, nor, col);
    bind_streams({std::span<const float>(pos).first(9 * count),
                  std::span<const float>(nor).first(9 * count),
                  {},
                  std::span<const uint8_t>(col).first(12 * count),
                  {}},
                 buffers);
    gl().glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(3 * count));
  }
  unbind_streams();
  gl().glDeleteBuffers(5, buffers.data());
}

void draw_lines(const std::vector<float>& lines, float width, const internal::Rgb& color) {
  if (lines.empty()) return;
  GLuint buffer = 0;
  gl().glGenBuffers(1, &buffer);
  gl().glBindBuffer(GL_ARRAY_BUFFER, buffer);
  gl().glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(lines.size() * sizeof(float)), lines.data(),
                    GL_STATIC_DRAW);
  gl().glEnableClientState(GL_VERTEX_ARRAY);
  gl().glVertexPointer(3, GL_FLOAT, 0, nullptr);
  gl().glLineWidth(width);
  gl().glColor3ub(color[0], color[1], color[2]);
  gl().glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(lines.size() / 3));
  gl().glDisableClientState(GL_VERTEX_ARRAY);
  gl().glBindBuffer(GL_ARRAY_BUFFER, 0);
  gl().glDeleteBuffers(1, &buffer);
}

//! The colour bar of the distortion view, drawn in render-target pixels (`scale` = supersampling).
void draw_legend_bar(const LegendBox& box, int target_width, int target_height, int scale) {
  const LegendBar bar = legend_bar(box, target_height, scale);
  const std::vector<float>& xy = bar.xy;
  const std::vector<uint8_t>& rgba = bar.rgba;
  const size_t frame_vertices = bar.frame_vertices;
  gl().glMatrixMode(GL_PROJECTION);
  const Mat4 ortho = orthographic(target_width, target_height);
  gl().glLoadMatrixf(ortho.data());
  gl().glMatrixMode(GL_MODELVIEW);
  gl().glLoadIdentity();
  gl().glDisable(GL_DEPTH_TEST);
  gl().glDisable(GL_LIGHTING);
  gl().glDisable(GL_TEXTURE_2D);
  gl().glShadeModel(GL_SMOOTH);
  gl().glEnableClientState(GL_VERTEX_ARRAY);
  gl().glEnableClientState(GL_COLOR_ARRAY);
  gl().glVertexPointer(2, GL_FLOAT, 0, xy.data());
  gl().glColorPointer(4, GL_UNSIGNED_BYTE, 0, rgba.data());
  gl().glDrawArrays(GL_TRIANGLE_STRIP, 0, static_cast<GLsizei>(frame_vertices));
  gl().glDrawArrays(GL_TRIANGLE_STRIP, static_cast<GLint>(frame_vertices),
                    static_cast<GLsizei>(xy.size() / 2 - frame_vertices));
  gl().glDisableClientState(GL_COLOR_ARRAY);
  gl().glDisableClientState(GL_VERTEX_ARRAY);
}

}  // namespace

Status render_preview(const Mesh& mesh, std::span<const float> corner_uv, std::span<const uint32_t> patch,
                      const Image* texture, const RenderOptions& options, Image& out) {
  return render_preview(mesh, corner_uv, patch, texture, PreviewMaterial{}, options, out);
}

Status render_preview(const Mesh& mesh, std::span<const float> corner_uv, std::span<const uint32_t> patch,
                      const Image* texture, const PreviewMaterial& material, const RenderOptions& options, Image& out) {
  out = Image{};
  TAILOR_RETURN_IF_ERROR(check_inputs(mesh, corner_uv, patch, texture, material, options));
  try {
    // Supersampling is reduced rather than refused when the target would get too large.
    int scale = options.supersample;
    while (scale > 1 && (options.width * scale > kMaxRenderSide || options.height * scale > kMaxRenderSide)) --scale;
    const int target_width = options.width * scale;
    const int target_height = options.height * scale;

    PreviewScene scene;
    if (texture != nullptr && !texture->empty()) {
      scene.texture_width = texture->width;
      scene.texture_height = texture->height;
    }
    prepare_scene(mesh, corner_uv, patch, options, scene);
    const bool textured = options.view == PreviewView::kTexture || options.view == PreviewView::kChecker;

    std::string gl_error;
    if (!internal::load_gl_api(gl_error)) return Status::error(ErrorCode::kUnsupported, "", gl_error);
    OffscreenContext context;
    if (!context.create(target_width, target_height)) {
      return Status::error(ErrorCode::kUnsupported, "", "cannot create an off-screen OpenGL context (OSMesa)");
    }
    GLint max_texture = 0;
    gl().glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture);
    const bool use_image = options.view == PreviewView::kTexture && texture != nullptr;
    bool shaded = options.view == PreviewView::kTexture;  // lit per pixel, with the material's maps
    const Image* normal_map = shaded ? material.normal : nullptr;
    const Image* occlusion_map = shaded ? material.occlusion : nullptr;
    for (const Image* image : {use_image ? texture : nullptr, normal_map, occlusion_map}) {
      if (image != nullptr && (image->width > max_texture || image->height > max_texture)) {
        return Status::error(ErrorCode::kUnsupported, "", "texture larger than the renderer allows",
                             std::to_string(max_texture) + " pixels a side");
      }
    }
    ShaderProgram program;  // after the context: deleted before it
    std::string shader_log;
    if (shaded && !program.build(shader_log)) {
      // Without GLSL (an OSMesa without llvmpipe) the fixed-function light still draws the texture.
      if (normal_map != nullptr || occlusion_map != nullptr)
        return Status::error(ErrorCode::kUnsupported, "", "the renderer cannot compile its shader", shader_log);
      shaded = false;
    }
    // The normal map's tangent frames: the file's, else those export_mesh would write for these UVs.
    std::vector<float> computed_tangents;
    std::span<const float> tangents = material.corner_tangents;
    if (normal_map != nullptr && tangents.empty()) {
      TAILOR_RETURN_IF_ERROR(corner_tangents(mesh, corner_uv, computed_tangents));
      tangents = computed_tangents;
    }

    // The distortion view keeps a band at the bottom for its legend, so the mesh never hides it.
    const LegendBox box = legend_box(options.width, options.height);
    const int band = options.view == PreviewView::kDistortion ? options.height - box.y + box.height : 0;
    gl().glViewport(0, band * scale, target_width, target_height - band * scale);
    gl().glClearColor(kBackground[0] / 255.0f, kBackground[1] / 255.0f, kBackground[2] / 255.0f, 1.0f);
    gl().glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    gl().glEnable(GL_DEPTH_TEST);
    gl().glDepthFunc(GL_LEQUAL);

    const Camera camera = place_camera(scene.frame, options, band);
    gl().glMatrixMode(GL_PROJECTION);
    gl().glLoadMatrixf(camera.projection.data());

    // Light fixed in eye space (up-left of the camera) before the view matrix is loaded.
    gl().glMatrixMode(GL_MODELVIEW);
    gl().glLoadIdentity();
    const std::array<GLfloat, 4> light_dir = {-0.35f, 0.55f, 0.76f, 0.0f};
    const std::array<GLfloat, 4> diffuse = {0.72f, 0.72f, 0.72f, 1.0f};
    const std::array<GLfloat, 4> ambient = {0.0f, 0.0f, 0.0f, 1.0f};
    const std::array<GLfloat, 4> scene_ambient = {0.36f, 0.36f, 0.36f, 1.0f};
    gl().glLightfv(GL_LIGHT0, GL_POSITION, light_dir.data());
    gl().glLightfv(GL_LIGHT0, GL_DIFFUSE, diffuse.data());
    gl().glLightfv(GL_LIGHT0, GL_AMBIENT, ambient.data());
    gl().glLightModelfv(GL_LIGHT_MODEL_AMBIENT, scene_ambient.data());
    gl().glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_TRUE);  // open meshes show their inside lit too
    gl().glEnable(GL_LIGHTING);
    gl().glEnable(GL_LIGHT0);
    gl().glEnable(GL_COLOR_MATERIAL);
    gl().glColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
    gl().glShadeModel(GL_SMOOTH);
    gl().glLoadMatrixf(camera.view.data());
    gl().glMultMatrixf(camera.turn.data());

    gl().glColor4ub(255, 255, 255, 255);
    Texture gl_texture, gl_normal, gl_occlusion;  // after the context: deleted before it
    if (normal_map != nullptr || occlusion_map != nullptr) {
      if (normal_map != nullptr) {
        gl().glActiveTexture(GL_TEXTURE1);
        upload_texture(*normal_map, gl_normal);
      }
      if (occlusion_map != nullptr) {
        gl().glActiveTexture(GL_TEXTURE2);
        upload_texture(*occlusion_map, gl_occlusion);
      }
      gl().glActiveTexture(GL_TEXTURE0);
    }
    if (textured) {
      if (use_image) {
        upload_texture(*texture, gl_texture);
      } else {
        const bool checker = options.view == PreviewView::kChecker;
        upload_texture(
            checker ? checker_image(kCheckerDark, kCheckerLight) : checker_image(kNeutralDark, kNeutralLight),
            gl_texture);
        // The generated image holds 2x2 squares.
        gl().glMatrixMode(GL_TEXTURE);
        gl().glLoadIdentity();
        gl().glScalef(options.checker_squares / 2.0f, options.checker_squares / 2.0f, 1.0f);
        gl().glMatrixMode(GL_MODELVIEW);
      }
    }
    // Seams are drawn on top of the faces: push the faces back a little.
    gl().glEnable(GL_POLYGON_OFFSET_FILL);
    gl().glPolygonOffset(1.0f, 1.0f);

    if (shaded) {
      gl().glUseProgram(program.id());
      gl().glUniform1i(program.uniform("base_map"), 0);
      gl().glUniform1i(program.uniform("normal_map"), 1);
      gl().glUniform1i(program.uniform("occlusion_map"), 2);
      gl().glUniform1i(program.uniform("has_normal"), normal_map != nullptr ? 1 : 0);
      gl().glUniform1i(program.uniform("has_occlusion"), occlusion_map != nullptr ? 1 : 0);
      const float length =
          std::sqrt(light_dir[0] * light_dir[0] + light_dir[1] * light_dir[1] + light_dir[2] * light_dir[2]);
      gl().glUniform3f(program.uniform("light_dir"), light_dir[0] / length, light_dir[1] / length,
                       light_dir[2] / length);
      draw_split_surface(mesh, corner_uv, true, scene.normals, scene.frame, tangents);
      gl().glUseProgram(0);
    } else if (textured) {
      draw_split_surface(mesh, corner_uv, true, scene.normals, scene.frame);
    } else if (options.view == PreviewView::kPatches) {
      draw_patch_surface(mesh, scene.patch_ids, scene.normals, scene.frame);
    } else {
      draw_face_colored_surface(mesh, scene.face_colors, scene.normals, scene.frame);
    }
    gl().glDisable(GL_POLYGON_OFFSET_FILL);
    gl().glDisable(GL_LIGHTING);
    gl().glDisable(GL_TEXTURE_2D);
    if (options.view == PreviewView::kSeams) {
      draw_lines(scene.invisible_lines, 2.0f * static_cast<float>(scale), internal::kInvisibleSeamColor);
      draw_lines(scene.lines, 2.0f * static_cast<float>(scale), internal::kVisibleSeamColor);
    } else {
      draw_lines(scene.lines, 1.25f * static_cast<float>(scale), kSeamColor);
    }

    gl().glViewport(0, 0, target_width, target_height);
    if (options.view == PreviewView::kDistortion) draw_legend_bar(box, target_width, target_height, scale);
    gl().glFinish();
    if (gl().glGetError() == GL_OUT_OF_MEMORY) {
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
