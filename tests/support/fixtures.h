// What several test programs need: meshes from tests/data and small generated ones, scratch
// folders, whole files and shell commands. Built once as the tailor_test_support library that
// every tests/<stage>_test.cpp links; the helpers that check something do so with gtest's
// non-fatal EXPECT (a failure is reported and the test goes on).
#pragma once

#include <string>

#include "tailor/io.h"
#include "tailor/mesh.h"

namespace tailor::test {

// === Meshes ======================================================================================

//! tests/data/meshes/<name>.
std::string mesh_path(const std::string& name);

//! The mesh tests/data/meshes/<name>; a failed load is a test failure (an empty mesh returned).
Mesh load_test_mesh(const std::string& name, LoadReport* report = nullptr);

//! How each cell of grid() is cut in two: kRising along (i, j) - (i+1, j+1), kFalling along
//! (i+1, j) - (i, j+1).
enum class Diagonal { kRising, kFalling };

//! A flat (z = 0) grid of nx by ny unit cells, two triangles per cell, all counter-clockwise seen
//! from +z. Vertex (i, j) = j*(nx+1)+i at (i, j, 0). Per cell: kRising (i,j) (i+1,j) (i+1,j+1),
//! (i,j) (i+1,j+1) (i,j+1); kFalling (i,j) (i+1,j) (i,j+1), (i+1,j) (i+1,j+1) (i,j+1).
Mesh grid(int nx, int ny, Diagonal diagonal);

//! Closed box [0,sx] x [0,sy] x [0,sz], outward faces: 8 shared vertices, 12 triangles.
Mesh box(float sx, float sy, float sz);

//! Closed axis-aligned box [0,sx]x[0,sy]x[0,sz], each side split into n by n quads (two
//! counter-clockwise triangles seen from outside). Vertices are not shared between sides, which is
//! enough for frames (topology then sees six open sheets).
Mesh box_sides(float sx, float sy, float sz, int n);

// === Files and commands ==========================================================================

//! This test program's scratch folder, <system temp>/tailor_<program>_<pid> (e.g.
//! /tmp/tailor_image_test_1234), created if missing and left behind for inspection.
std::string temp_dir();

//! temp_dir()/<name>.
std::string temp_path(const std::string& name);

//! An empty folder <system temp>/tailor_<program>_<pid>_<name> (emptied if it exists); the caller
//! removes it.
std::string empty_temp_dir(const std::string& name);

//! The whole file; a failed read is a test failure (an empty string returned).
std::string read_all(const std::string& file);

//! A JPEG file's bytes with an EXIF block (APP1 after the start marker) whose IFD0 holds only the
//! Orientation tag, 1..8, in little- or big-endian TIFF order: what a phone writes.
std::string with_exif_orientation(const std::string& jpeg, int orientation, bool little_endian = true);

//! Runs a shell command and returns its exit status (-1 if it did not exit). Without `err` its
//! stdout and stderr both go to `out`; with it, stderr goes to *err.
int run_command(const std::string& command, std::string& out, std::string* err = nullptr);

}  // namespace tailor::test
