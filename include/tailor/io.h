// tailor: mesh readers (PLY, OBJ, OFF, STL, and glTF binary for evaluating UV-mapped meshes).
//
// All readers are safe for untrusted input: every count read from a header is checked against the
// bytes actually present before anything is allocated, every index is range-checked and every
// coordinate must be finite. On failure the output mesh is left empty and the Status says what
// went wrong and where ("line 17", "face 3071", "byte 4096").
//
// After parsing, every reader runs the same clean-up (finalize_mesh): faces with a repeated vertex
// are dropped, exact duplicate faces are dropped, zero-area faces and unreferenced vertices are
// kept; all of it is counted in the LoadReport.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tailor/api.h"
#include "tailor/mesh.h"
#include "tailor/orientation.h"
#include "tailor/progress.h"
#include "tailor/status.h"

namespace tailor {

enum class MeshFormat { kUnknown, kPly, kObj, kOff, kStl, kGlb, kGltf };

//! Format from the file extension (case-insensitive): .ply .obj .off .stl .glb .gltf; kUnknown otherwise.
TAILOR_API MeshFormat mesh_format_from_path(const std::string& path);

//! Reads a mesh file; the format comes from the extension, or from the content when the extension
//! is unknown. Cost: one pass over the file, O(F + V) memory.
TAILOR_API Status load_mesh(const std::string& path, Mesh& mesh, LoadReport* report = nullptr);

//! load_mesh with progress in [0, 1] (tailor/progress.h): the parse (PLY, OBJ, OFF and STL by bytes,
//! glTF by accessor data decoded; reported every few MB, never per element), then the repairs;
//! false cancels (kCancelled, the mesh left empty).
TAILOR_API Status load_mesh(const std::string& path, Mesh& mesh, LoadReport* report, const ProgressCallback& progress);

//! Parses a mesh held in memory (used by the fuzzers and the truncation tests).
//! `name` is only used in error messages. A .gltf whose buffers are files fails with kUnsupported
//! here (no file is opened); load_mesh reads them from the .gltf's folder.
TAILOR_API Status read_mesh(std::span<const char> data, MeshFormat format, const std::string& name, Mesh& mesh,
                            LoadReport* report = nullptr);

//! Reads a seam-face list: one 0-based face index per line ('#' comments and blank lines allowed),
//! and sets seam_faces[f] = 1 for each (seam_faces is resized to face_count, zeros elsewhere).
//! Face indices refer to the mesh as loaded (after finalize_mesh dropped degenerate faces).
//! Fails with the line number on a malformed or out-of-range index.
TAILOR_API Status load_seam_faces(const std::string& path, size_t face_count, std::vector<uint8_t>& seam_faces);

//! Reads orientation strokes (OrientationOptions::strokes) from JSON text of the form
//! {"strokes": [{"points": [[x, y, z], ...], "radius": r}, ...]} (mesh coordinates; what
//! `tailor map --strokes` and the edit API read). Fails with kParse naming `name` and where
//! (byte N, strokes[i].points[k], ...) on invalid JSON, a missing or mistyped key, an unknown key,
//! fewer than 2 points, a coordinate that is not a finite float or a radius not > 0; `strokes` is
//! then empty. O(size of the text).
TAILOR_API Status parse_strokes(std::string_view text, const std::string& name,
                                std::vector<OrientationStroke>& strokes);

//! parse_strokes on the contents of a file (kIo when it cannot be read).
TAILOR_API Status load_strokes(const std::string& path, std::vector<OrientationStroke>& strokes);

//! The JSON parse_strokes reads, one line (floats written so that they read back bit for bit).
TAILOR_API std::string strokes_json(std::span<const OrientationStroke> strokes);

//! Validation and repair shared by all readers (see top of file). Fails on non-finite positions,
//! out-of-range indices, more than kMaxFaces faces, and meshes with no face left.
TAILOR_API Status finalize_mesh(const std::string& name, Mesh& mesh, LoadReport& report);

}  // namespace tailor
