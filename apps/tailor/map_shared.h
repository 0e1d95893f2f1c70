// What `tailor map` and `tailor edit` share so that an edit saved by the tool and replayed with
// `tailor map` gives the same bytes: the --axis text, and the export step (texture or material
// embedding, export_mesh's options).
#pragma once

#include <string>

#include "tailor/atlas.h"
#include "tailor/export.h"
#include "tailor/mesh.h"
#include "tailor/orientation.h"
#include "tailor/status.h"

namespace tailor::cli {

//! --axis as the user writes it: pca, skeleton, x, y, z or X,Y,Z (the inverse of parse_axis).
std::string axis_text(const OrientationOptions& o);

//! Parses --axis (pca, skeleton, x, y, z or three numbers X,Y,Z; not auto, which the commands resolve
//! by choose_orientation_axis). Fails with kInvalidArgument naming the text.
Status parse_axis(const std::string& text, OrientationOptions& o);

//! The output side of a mapping, as given on the command line of `tailor map`.
struct MeshOutput {
  std::string texture_path;   //!< the colour image embedded (or referenced by the .mtl); "" none
  MaterialTextures material;  //!< --material's other maps (.glb)
  int texture_width = 0;      //!< the UV lattice: UVs are written as pixels / this
  int texture_height = 0;
  MeshCompression compression = MeshCompression::kNone;
  int uv_set = 0;
  SceneUp up = SceneUp::kY;
};

//! Writes `mesh` with the UVs of `atlas` to `path` (export_mesh; atomic, staged in an active FileBatch),
//! reporting to `progress` (optional; ExportOptions::progress).
Status write_mapped_mesh(const std::string& path, const Mesh& mesh, const Atlas& atlas, const MeshOutput& output,
                         const ProgressCallback& progress = {});

}  // namespace tailor::cli
