// tailor: the triangle mesh, as flat arrays.
//
// Struct of arrays, 32-bit indices, nothing allocated per element. Polygons are fan-triangulated
// by the readers, so a Mesh always holds triangles.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace tailor {

//! Sentinel for "no element" in every uint32 id array (opposite edge, patch, vertex...).
inline constexpr uint32_t kInvalid = std::numeric_limits<uint32_t>::max();

//! Largest number of faces tailor indexes: corner ids 3F must fit in uint32 below kInvalid.
inline constexpr size_t kMaxFaces = (size_t{kInvalid} - 1) / 3;
//! Largest number of vertices: 2^31 - 1, so that topology can pack (vertex, direction) in 32 bits.
//! (Positions alone would take 24 GiB at that count.)
inline constexpr size_t kMaxVertices = (size_t{1} << 31) - 1;

//! A per-corner attribute a file carried and export writes back (normals, colours, other UV sets).
struct CornerAttribute {
  std::string name;           //!< glTF semantic: "NORMAL", "COLOR_0", "TEXCOORD_1"...
  int components = 0;         //!< 2, 3 or 4
  std::vector<float> values;  //!< #F*3 by components, per corner (unit normals; linear RGBA colours in [0, 1])
};

//! Where the faces of a glTF scene came from, so that export can give them back their names,
//! extras and materials (the geometry itself stays one mesh in world space). JSON values are kept
//! as JSON text ("" when absent); export writes them back as they are.
struct SceneParts {
  //! One mesh instance of the scene: the node that placed it and the mesh it placed.
  struct Instance {
    std::string node_name, node_extras, mesh_name, mesh_extras;
  };
  //! The faces of one instance that share one material (a glTF primitive of the output).
  struct Part {
    uint32_t instance = 0;         //!< into instances
    uint32_t material = kInvalid;  //!< into materials; kInvalid: none (tailor's default material)
  };
  std::string asset_extras, asset_copyright, scene_name, scene_extras;
  std::vector<Instance> instances;
  //! The input materials used, as JSON objects without their textures and extensions (name,
  //! factors, alphaMode, alphaCutoff, doubleSided, emissiveFactor, extras): export adds its own maps.
  std::vector<std::string> materials;
  std::vector<Part> parts;
  bool empty() const { return parts.empty(); }
};

//! A triangle mesh.
//! Corner c = 3f + k is corner k of face f; indices[c] is its vertex.
struct Mesh {
  std::vector<float> positions;     //!< #V by 3, xyz packed; finite after loading
  std::vector<uint32_t> indices;    //!< #F by 3, counter-clockwise; every index < #V after loading
  std::vector<float> corner_uvs;    //!< empty, or #F*3 by 2: texture coordinates from the file, per corner,
                                    //!< in texture repeats (1.0 = one texture width), v up as in OBJ/glTF-flipped
  std::vector<uint8_t> seam_faces;  //!< empty, or #F flags: 1 = user-marked seam face (PLY `seam` property)
  std::vector<CornerAttribute> corner_attributes;  //!< kept from the file (glTF NORMAL, COLOR_0, TEXCOORD_n
                                                   //!< n > 0), written back by export; not used by the mapping
  std::vector<uint32_t> face_parts;  //!< empty, or #F: the scene part of each face (glTF; index into scene.parts)
  SceneParts scene;                  //!< glTF: names, extras and materials of the parts, written back by export

  size_t vertex_count() const { return positions.size() / 3; }
  size_t face_count() const { return indices.size() / 3; }
  bool empty() const { return indices.empty(); }
};

//! What a reader saw and repaired. Repairs are counted, never silent.
struct LoadReport {
  std::string format;  //!< e.g. "PLY binary_little_endian", "OBJ", "OFF", "STL binary"
  size_t file_bytes = 0;
  size_t source_faces = 0;             //!< faces/polygons/strip triangles as stored in the file
  size_t polygons_triangulated = 0;    //!< source polygons with more than 3 vertices (fan-triangulated)
  size_t concave_polygons = 0;         //!< of those, concave ones cut into ears instead (a fan would overlap)
  size_t degenerate_faces = 0;         //!< triangles with a repeated vertex index: dropped
  size_t duplicate_faces = 0;          //!< triangles with the same vertex set as an earlier one: dropped
  size_t zero_area_faces = 0;          //!< distinct vertices but zero area: kept
  size_t unreferenced_vertices = 0;    //!< vertices no face uses: kept, so vertex ids match the file
  size_t welded_vertices = 0;          //!< STL: corners merged into shared vertices (bit-identical positions)
  size_t faces_collapsed_by_weld = 0;  //!< glTF: faces whose corners were distinct vertices at one position, so
                                       //!< repeat a vertex once the split vertices are welded (counted in
                                       //!< degenerate_faces and dropped)
  size_t faces_without_uv = 0;         //!< OBJ: faces without vt where other faces have them; glTF: faces of the
                                       //!< triangle primitives without the TEXCOORD set others have (then no
                                       //!< face keeps its texture coordinates: corner_uvs is empty)
  std::string primitive_without_uv;    //!< glTF: the first of those primitives, e.g. "mesh 1 'rock' primitive 0"
                                       //!< (the mesh's name when it has one); empty when none
  size_t faces_turned = 0;             //!< tailor map: faces wound against their neighbours, turned to run as
                                       //!< the surface around them (orient_faces_coherently)
  size_t mesh_instances = 0;           //!< glTF: meshes placed by the scene's nodes (world transforms applied)
  size_t skipped_primitives = 0;       //!< glTF: point and line primitives of those instances, not read
  std::string not_kept;                //!< what the file has that the output will not (", "-separated), e.g.
                                       //!< "material textures, TANGENT"; empty when nothing is lost
  std::string not_read;                //!< what the reader read past ("; "-separated): lines after what an OFF
                                       //!< or ascii PLY header declares, e.g. "3 lines after the 1 face the
                                       //!< OFF header declares (from line 8)"; a PLY property of a role an
                                       //!< earlier one has, e.g. "PLY vertex property s (u before it is
                                       //!< read in its place)"; empty when none
  int texture_width = 0;               //!< the base colour texture's size, read from its header without decoding
  int texture_height = 0;              //!< it, any size. glTF (read_glb_file): embedded, or given by a URI (a
                                       //!< data: URI, a file next to the .gltf); OBJ (load_mesh of a path): the
                                       //!< first map_Kd of the .mtl its mtllib names; PLY (load_mesh of a path):
                                       //!< its `comment TextureFile` (MeshLab's, and tailor's .ply writer's).
                                       //!< 0: none, or no header read
  bool texture_file = false;  //!< that texture is a file next to the .gltf, .mtl or .ply (only its header read)
  std::string texture_path;   //!< OBJ, PLY and a .gltf's image file: that file's path (empty: none, or no
                              //!< header read)
  std::string
      texture_named;  //!< the base colour texture the file names, even when its header could
                      //!< not be read (OBJ, PLY, a .gltf's image file: its path; else glTF: "image N"); empty: none
  std::string texture_problem;     //!< glTF read with its texture (read_glb_file): why the embedded base colour
                                   //!< image was not decoded (its bytes are not an image, or corrupt); the
                                   //!< texture is then left empty. Empty: decoded, or none
  bool texture_transform = false;  //!< glTF: the base colour texture carries KHR_texture_transform, which is
                                   //!< not applied (UVs are read, measured and drawn as stored)
  uint32_t texture_symmetry = 1;   //!< 4 where the file says the map is 4-fold (written by tailor map
                                   //!< --symmetry 4: ExportOptions::symmetry): glb: that texture's material
                                   //!< (without a texture, the first primitive's); OBJ: its .mtl; else 1
  double load_seconds = 0.0;
};

}  // namespace tailor
