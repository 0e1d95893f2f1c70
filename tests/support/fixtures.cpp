// The shared test fixtures (fixtures.h).
#include "support/fixtures.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "util/atomic_file.h"

namespace tailor::test {
namespace {

namespace fs = std::filesystem;

//! <system temp>/tailor_<program>_<pid>: the program's name tells the test programs apart, the
//! process id the runs (ctest runs each test in a process of its own).
fs::path process_scratch_path() {
  return fs::temp_directory_path() /
         ("tailor_" + std::string(program_invocation_short_name) + "_" + std::to_string(getpid()));
}

}  // namespace

// === Meshes ======================================================================================

std::string mesh_path(const std::string& name) { return std::string(TAILOR_TEST_DATA) + "/meshes/" + name; }

Mesh load_test_mesh(const std::string& name, LoadReport* report) {
  Mesh mesh;
  const Status s = load_mesh(mesh_path(name), mesh, report);
  EXPECT_TRUE(s.is_ok()) << name << ": " << s.message();
  return mesh;
}

Mesh grid(int nx, int ny, Diagonal diagonal) {
  Mesh mesh;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      mesh.positions.push_back(static_cast<float>(i));
      mesh.positions.push_back(static_cast<float>(j));
      mesh.positions.push_back(0.0f);
    }
  const auto id = [nx](int i, int j) { return static_cast<uint32_t>(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (diagonal == Diagonal::kRising) {
        mesh.indices.insert(mesh.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        mesh.indices.insert(mesh.indices.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        mesh.indices.insert(mesh.indices.end(), {id(i, j), id(i + 1, j), id(i, j + 1)});
        mesh.indices.insert(mesh.indices.end(), {id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  return mesh;
}

Mesh box(float sx, float sy, float sz) {
  Mesh m;
  for (int i = 0; i < 8; ++i)
    m.positions.insert(m.positions.end(), {(i & 1) ? sx : 0.f, (i & 2) ? sy : 0.f, (i & 4) ? sz : 0.f});
  m.indices = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
               2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  return m;
}

Mesh box_sides(float sx, float sy, float sz, int n) {
  Mesh mesh;
  const float size[3] = {sx, sy, sz};
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const uint32_t base = static_cast<uint32_t>(mesh.vertex_count());
      for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
          float p[3];
          p[axis] = side ? size[axis] : 0.f;
          p[u] = size[u] * static_cast<float>(i) / static_cast<float>(n);
          p[v] = size[v] * static_cast<float>(j) / static_cast<float>(n);
          mesh.positions.insert(mesh.positions.end(), p, p + 3);
        }
      auto id = [&](int i, int j) { return base + static_cast<uint32_t>(j * (n + 1) + i); };
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          // (u, v, axis) is right-handed: counter-clockwise in (u, v) faces +axis.
          if (side) {
            mesh.indices.insert(mesh.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            mesh.indices.insert(mesh.indices.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
          } else {
            mesh.indices.insert(mesh.indices.end(), {id(i, j), id(i + 1, j + 1), id(i + 1, j)});
            mesh.indices.insert(mesh.indices.end(), {id(i, j), id(i, j + 1), id(i + 1, j + 1)});
          }
        }
    }
  }
  return mesh;
}

// === Files and commands ==========================================================================

std::string temp_dir() {
  const fs::path dir = process_scratch_path();
  fs::create_directories(dir);
  return dir.string();
}

std::string temp_path(const std::string& name) { return (fs::path(temp_dir()) / name).string(); }

std::string empty_temp_dir(const std::string& name) {
  const fs::path dir = process_scratch_path().string() + "_" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::string read_all(const std::string& file) {
  std::string bytes;
  EXPECT_TRUE(internal::read_file(file, bytes).is_ok()) << file;
  return bytes;
}

int run_command(const std::string& command, std::string& out, std::string* err) {
  out.clear();
  const std::string err_file = err ? temp_path("stderr.txt") : std::string();
  const std::string redirect = err ? " 2>'" + err_file + "'" : std::string(" 2>&1");
  FILE* pipe = popen((command + redirect).c_str(), "r");
  if (!pipe) return -1;
  char buffer[4096];
  size_t n = 0;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) out.append(buffer, n);
  const int status = pclose(pipe);
  if (err && !internal::read_file(err_file, *err).is_ok()) err->clear();
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string with_exif_orientation(const std::string& jpeg, int orientation, bool little_endian) {
  const auto u16 = [&](int v) {
    return little_endian ? std::string{static_cast<char>(v & 255), static_cast<char>(v >> 8)}
                         : std::string{static_cast<char>(v >> 8), static_cast<char>(v & 255)};
  };
  // TIFF header (byte order, 42, IFD0 at 8), IFD0: one entry (tag, SHORT, count 1, value), no next.
  std::string tiff = little_endian ? std::string("II\x2a\0\x08\0\0\0", 8) : std::string("MM\0\x2a\0\0\0\x08", 8);
  tiff += u16(1) + u16(0x0112) + u16(3) + (little_endian ? std::string("\1\0\0\0", 4) : std::string("\0\0\0\1", 4)) +
          u16(orientation) + u16(0) + std::string(4, '\0');
  const std::string body = std::string("Exif\0\0", 6) + tiff;
  const size_t length = body.size() + 2;
  const std::string app1 =
      std::string("\xff\xe1") + static_cast<char>(length >> 8) + static_cast<char>(length & 255) + body;
  return jpeg.substr(0, 2) + app1 + jpeg.substr(2);
}

}  // namespace tailor::test
