// What `tailor map` and `tailor edit` share so that an edit saved by the tool and replayed with
// `tailor map` gives the same bytes: the mapping options (their flags and the parsing of those given as
// text), the --axis text, and the export step (texture or material embedding, export_mesh's options).
#pragma once

#include <string>

#include "tailor/atlas.h"
#include "tailor/export.h"
#include "tailor/mapping.h"
#include "tailor/mesh.h"
#include "tailor/orientation.h"
#include "tailor/status.h"
#include "tailor/topology.h"

namespace CLI {
class Option;
class Option_group;
}  // namespace CLI

namespace tailor::cli {

//! --axis as the user writes it: pca, skeleton, x, y, z or X,Y,Z (the inverse of parse_axis).
std::string axis_text(const OrientationOptions& o);

//! The shortest text that reads back as the same float (0.02, not 0.0199999996): options echoed in
//! commands and replies.
std::string float_text(float x);

//! Parses --axis (pca, skeleton, x, y, z or three numbers X,Y,Z; not auto, which the commands resolve
//! by choose_orientation_axis). Fails with kInvalidArgument naming the text.
Status parse_axis(const std::string& text, OrientationOptions& o);

//! The mapping options of `tailor map` and `tailor edit` given as text (parsed by apply_mapping_args);
//! the others are bound to their MapTextureOptions fields by add_mapping_options.
struct MappingArgs {
  std::string mode = mapping_mode_name(MappingOptions{}.mode);
  std::string axis = axis_text(OrientationOptions{});  // or auto (resolved by choose_orientation_axis)
  std::string field_following = "auto";                // or a number in [0, 1]
  std::string chunks = "auto";                         // --chunks auto|on|off
  std::string chunk_cell = "auto";                     // --chunk-cell: a power-of-two exponent, or auto
  bool crack_rings_given = false;                      // --crack-rings on the command line (kept over auto's)
  bool symmetry_given = false;                         // --symmetry on the command line (kept over a material's)
  std::string patches_only_given;                      // the first option given that only --mode patches reads
  bool threshold_given = false;                        // --threshold (only --mode thesis reads it)
  std::string seed_point;
  std::string seam_faces;                            // --seam-faces: a file of face ids
  std::string strokes;                               // --strokes: orientation strokes, JSON (read_strokes.cpp)
  int texture_size = ExportOptions{}.texture_width;  // --texture-size, when no texture gives it

  bool auto_axis() const { return axis == "auto"; }
  bool auto_field_following() const { return field_following == "auto"; }
};

//! The options add_mapping_options made that a command refines or reads after parsing.
struct MappingOptionHandles {
  CLI::Option* crack_rings = nullptr;  // its count() sets MappingArgs::crack_rings_given
  CLI::Option* smooth = nullptr;
  CLI::Option* symmetry = nullptr;  // its count() sets MappingArgs::symmetry_given
  CLI::Option* scale = nullptr;
  CLI::Option* threshold = nullptr;
  std::vector<CLI::Option*> patches_only;  // what the thesis mode does not read (its growth has no bound)
};

//! After parsing: which of the handles' options the command line gave (MappingArgs' *_given).
void note_given_options(const MappingOptionHandles& handles, MappingArgs& args);

//! Adds the mapping options (--mode ... --symmetry) to `group`, in the order of --help, bound to `args`
//! and `options`. `with_input_files`: --seam-faces and --strokes go in the group too (before
//! --symmetry), as in `tailor map`; `tailor edit` lists them with its files.
MappingOptionHandles add_mapping_options(CLI::Option_group* group, MappingArgs& args, MapTextureOptions& options,
                                         bool with_input_files);

//! Parses the options given as text into `options` (an axis of auto is left to the command) and checks
//! them and the bound ones (check_map_options), in the order the commands report them. Fails with
//! kInvalidArgument naming the option.
//! Parses --chunks (auto, on, off) and --chunk-cell (auto or a whole number in -60..60) into `chunks`.
Status parse_chunk_args(const std::string& mode, const std::string& cell, ChunkOptions& chunks);

Status apply_mapping_args(const MappingArgs& args, MapTextureOptions& options);

//! The output side of a mapping, as given on the command line of `tailor map`.
struct MeshOutput {
  std::string texture_path;   //!< the colour image embedded (or referenced by the .mtl); "" none
  MaterialTextures material;  //!< --material's other maps (.glb)
  int texture_width = 0;      //!< the UV lattice: UVs are written as pixels / this
  int texture_height = 0;
  MeshCompression compression = MeshCompression::kNone;
  int uv_set = 0;
  SceneUp up = SceneUp::kY;
  uint32_t symmetry = 1;  //!< the map's (MappingOptions::symmetry): 4 is recorded in the .glb (ExportOptions)
  std::vector<std::string> other_outputs;  //!< the run's other files (ExportOptions::other_outputs)
  const Image* texture_image = nullptr;    //!< texture_path's pixels, as loaded (ExportOptions::texture_image)
};

//! Writes `mesh` with the UVs of `atlas` to `path` (export_mesh; atomic, staged in an active FileBatch),
//! reporting to `progress` (optional; ExportOptions::progress).
Status write_mapped_mesh(const std::string& path, const Mesh& mesh, const Atlas& atlas, const MeshOutput& output,
                         const ProgressCallback& progress = {});

//! Warns (one line each) of what `input` holds that the map neither reads nor keeps: load.not_kept,
//! load.not_read and the point and line primitives skipped (tailor map and tailor edit alike).
void warn_unused_input(const std::string& input, const LoadReport& load, bool quiet);

//! Turns the faces of `mesh` wound against their neighbours (orient_faces_coherently over
//! `topology`, the mesh's), counts them in load.faces_turned and says how many in one warning line
//! ending in `hint`. True when any turned: `topology` then no longer describes the mesh.
bool turn_wound_faces(const std::string& input, Mesh& mesh, const Topology& topology, LoadReport& load, bool quiet,
                      const std::string& hint = {});

}  // namespace tailor::cli
