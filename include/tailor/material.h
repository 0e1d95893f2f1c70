// tailor: a PBR material's maps (a folder or a JSON naming them) turned into the glTF material of a
// .glb (export.h MaterialTextures): base colour embedded as is, the normal map in glTF's (GL)
// convention, roughness and metallic packed as glTF wants (G and B), occlusion in R.
#pragma once

#include <string>
#include <vector>

#include "tailor/api.h"
#include "tailor/export.h"
#include "tailor/image.h"
#include "tailor/status.h"

namespace tailor {

//! The role of a map, from its file name's suffix (material_role_from_name).
enum class MaterialRole { kNone, kColor, kNormal, kRoughness, kMetallic, kOcclusion, kHeight };

//! The role a file's name claims: its stem (case-insensitive) ends with a known word after _ - . or
//! space (or is that word): color/colour/basecolor/base_color/albedo/diffuse, normal/nor/nrm (with
//! _gl/_dx: normal_dx sets *directx), roughness/rough, metallic/metalness/metal, ao/occlusion/
//! ambientocclusion, height/disp/displacement/bump. kNone for any other name.
TAILOR_API MaterialRole material_role_from_name(const std::string& file_name, bool* directx = nullptr);

//! A material read by load_material.
struct MaterialMaps {
  std::string color;  //!< the base colour map's path (embedded as is), or empty
  int width = 0;      //!< the texture size, i.e. the UV lattice: the colour map's (else the first map's)
  int height = 0;
  MaterialTextures textures;  //!< the other maps, encoded for the .glb
  Image normal_image;         //!< the normal map as embedded (GL convention), 8 bits: for previews (render.h); or empty
  Image occlusion_image;      //!< the occlusion map, one 8-bit channel: for previews; or empty
  std::vector<std::string> files;  //!< every map read, "role: path", for reports
  std::vector<std::string> notes;  //!< one-line warnings (height map not embedded, ...)
  //! What the material JSON (or a folder's material.json) records as "symmetry": 4 for the
  //! quarter-turn tiles of `tailor tile --set --symmetry 4`, which `tailor map` and tailor.map then
  //! map with symmetry 4 unless told otherwise; 1 for plain tiles; 0 when it says nothing.
  int symmetry = 0;
};

//! Reads a material: a folder (its .png/.jpg/.jpeg files with a recognised suffix; others ignored) or
//! a JSON file, either {"color": "a.png", "normal": "b.png", ..., "normal_convention": "gl"} or the
//! material.json of `tailor tile --set` ({"maps": [{"file": ..., "normal": true}, ...]}: roles from
//! "role"/"type" or the file names). Paths are relative to the JSON's folder. A DX normal map
//! (normal_convention "dx" or a _dx/_directx suffix) has its green channel flipped. 16-bit maps
//! stay 16-bit. A "symmetry" of 1 or 4 in the JSON, or in a folder's material.json, fills
//! MaterialMaps::symmetry. Fails (kInvalidArgument, one line naming the file) when no map is
//! recognised, two files claim one role, maps differ in size, a symmetry is not 1 or 4; kIo /
//! kInvalidImage for unreadable files.
TAILOR_API Status load_material(const std::string& dir_or_json, MaterialMaps& out,
                                const ImageLoadOptions& options = {});

//! What the material.json of a tiled set records (`tailor tile --set`, tailor.tile_set), which
//! load_material reads back.
struct TileSetRecord {
  struct Map {
    std::string file;                   //!< its tile's file name in the folder (tile_set_file_name)
    std::string source;                 //!< the input it was tiled from, as given
    bool normal = false;                //!< a normal map
    int bits = 8, channels = 0;         //!< the input's (the tile keeps them)
    std::vector<std::string> variants;  //!< the variants' file names in order; empty for one tile
    bool directx = false;               //!< a DirectX normal map (+y down): recorded as "role": "normal_dx"
  };
  std::vector<Map> maps;
  std::string normal_convention = "gl";  //!< "gl" or "dx"
  int symmetry = 1;                      //!< 4: quarter-turn tiles, mapped with symmetry 4 (load_material)
  int width = 0, height = 0;             //!< the tiles' size
};

//! Writes folder/material.json for `record` (atomically; staged in an active internal::FileBatch).
TAILOR_API Status write_tile_set_record(const std::string& folder, const TileSetRecord& record);

}  // namespace tailor
