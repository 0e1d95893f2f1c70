// The Python module `tailor`: what the binding files share. One file per entry point
// (bind_mesh.cpp, bind_map.cpp, bind_tile.cpp, bind_eval.cpp, bind_save.cpp, bind_chunks.cpp,
// bind_tiles.cpp, bind_canonical.cpp, bind_stream_blocks.cpp); errors and the progress bridge in errors.cpp and
// progress.cpp. Every call releases the GIL while the library works.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tailor/atlas.h"
#include "tailor/chunked_mapper.h"
#include "tailor/mesh.h"
#include "tailor/status.h"

namespace tailor::python {

namespace py = pybind11;

//! A mesh as Python sees it: the library's Mesh, what loading it found, and where it came from.
struct PyMesh {
  Mesh mesh;
  LoadReport load;
  std::string source;  //!< the file it was loaded from, empty for arrays
};

//! What tailor.map returns: the atlas in pixels (for save), its texture size, and the reports.
struct PyResult {
  Atlas atlas;
  int texture_width = 0;
  int texture_height = 0;
  std::string texture;            //!< the texture file given to map (a material's colour map), empty when none
  std::string material;           //!< the material (folder or JSON) given to map, empty when none
  uint32_t symmetry = 1;          //!< map's symmetry: 4 is recorded in a .glb (ExportOptions::symmetry)
  std::vector<float> corner_uvs;  //!< #F*3*2, texture repeats, exactly as export writes them
  py::object stats;               //!< dict: the JSON of `tailor map --stats`
  double library_seconds = 0;     //!< wall time inside the library's calls (the benchmark's baseline)
};

//! Raises tailor.Error with the CLI's one-line message (what follows "tailor: error: ").
[[noreturn]] void raise_status(const Status& status);

//! `value` as a whole number for the bounded option `flag` (--crack-rings...): a non-whole value is
//! refused naming `name`, one outside the range in the words of tailor map (check_option_range).
uint32_t bounded_whole_number(const py::handle& value, const std::string& name, std::string_view flag);
//! Raises tailor.Error with `what` (a bad argument found by the binding itself).
[[noreturn]] void raise_error(const std::string& what);
//! `value` (an int, or anything with __index__ such as numpy's integers) when it is a whole number
//! in lo..hi; else tailor.Error naming `name` (pybind11's own casts raise a RuntimeError that names
//! neither the argument nor the range).
int64_t whole_number(const py::handle& value, const std::string& name, int64_t lo, int64_t hi);
//! `value` as a whole number (an int, or anything with __index__) into `out`, saturated to 64 bits;
//! false when it is none (whole_number's test, for callers with their own message).
bool whole_value(const py::handle& value, long long& out);

//! `o` as a numpy array (any array-like, as numpy.asarray reads it), or nothing when numpy cannot
//! read it as one; KeyboardInterrupt, SystemExit and MemoryError raised meanwhile pass through.
std::optional<py::array> as_array(const py::handle& o);

//! An (F, 3) array of int32, int64, uint32 or uint64 face indices -> `out` (3F uint32); a wrong
//! shape or dtype, or an index negative or not below vertex_count, raises tailor.Error naming `name`.
void copy_faces(const py::array& faces, size_t vertex_count, std::vector<uint32_t>& out, const char* name);

//! A read-only numpy view of `data` (shape given) that keeps `owner` alive: no copy.
template <class T>
py::array readonly_view(const T* data, std::vector<py::ssize_t> shape, py::handle owner) {
  py::array_t<T> view(std::move(shape), data, owner);
  py::detail::array_proxy(view.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return view;
}

//! "float32 (3, 4)": the dtype and shape of an array, for error messages.
std::string describe(const py::array& array);

//! Faces given by their corners, (F, 3, 3) float32 (the chunk rule's arithmetic on a streamed
//! mesh), checked (tailor.Error names what is wrong); and a streamed block's or tile's faces
//! (tailor.tiles): (F, 3) int64 vertex ids and their corners, a row each. Defined in
//! bind_stream_blocks.cpp.
using IdArray = py::array_t<int64_t, py::array::c_style | py::array::forcecast>;
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
FloatArray corner_array(const py::array& corners);
std::pair<IdArray, FloatArray> streamed_faces(const py::array& ids, const py::array& corners);

//! A sequence as the CLI's text of it ("0,1,0"), for messages; other objects as str() shows them.
std::string sequence_text(const py::handle& value);

//! The chunk_split argument of map() and ChunkedMapper(): None leaves `split_above` (the library's
//! default), else a face count in 0..2^32-1 (check_map_options then says 0 or at least 64).
void set_chunk_split(const py::object& chunk_split, uint32_t& split_above);

//! A path argument: str or os.PathLike, as a file system path.
std::string path_of(const py::handle& path);

//! `text` as a str, bytes that are not UTF-8 (a file name's) shown as U+FFFD: a str cannot hold them.
py::object utf8_text(const std::string& text);

//! Issues a UserWarning with `text` (bytes that are not UTF-8 replaced); throws what a warnings
//! filter that makes it an error raises.
void warn(const std::string& text);

//! A path the library gives back, as Python names files: os.fsdecode of its bytes (a name that is
//! not UTF-8 keeps its bytes as surrogate escapes, so that open() finds the file).
py::object path_text(const std::string& path);

//! Parses JSON text with Python's json module (the reports are text in the library).
py::object json_to_dict(const std::string& text);

//! Connects the library's progress callbacks to Python while the GIL is released: at most every
//! 50 ms (and at the end) it takes the GIL, checks for signals (Ctrl-C raises KeyboardInterrupt)
//! and calls the user's callback(fraction), 1.0 once; an exception there, or a false return value
//! other than None, cancels the work. finish() then re-raises that exception, or tailor.Error.
class ProgressBridge {
 public:
  explicit ProgressBridge(py::object callback) : callback_(std::move(callback)) {}
  //! The function to hand to the library (MappingOptions::progress, TileOptions::progress).
  std::function<bool(double)> function();
  //! Under the GIL, after the library returned `status`: raises what stopped it, or tailor.Error;
  //! on success the callback's last call says 1.0 (the library's last report may be earlier).
  void finish(const Status& status);

 private:
  bool report(double fraction);
  py::object callback_;
  std::mutex mutex_;
  std::optional<py::error_already_set> error_;
  bool stopped_by_callback_ = false;
  double last_fraction_ = -1;  //!< the last fraction the callback saw
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

//! Raises tailor.Error when `src` is an instance of the bound class `type` that was made by
//! `__new__` without `__init__` (pybind11 would hand its methods an unconstructed object).
void require_constructed(py::handle src, const std::type_info& type);

void bind_errors(py::module_& m);
void bind_mesh(py::module_& m);
void bind_map(py::module_& m);
void bind_tile(py::module_& m);
void bind_tile_set(py::module_& m);
void bind_eval(py::module_& m);
void bind_save(py::module_& m);
void bind_chunks(py::module_& m);
void bind_tiles(py::module_& m);

}  // namespace tailor::python

// The argument casters of the bound classes: an object made by `Cls.__new__(Cls)` and never
// initialised holds no C++ object, and pybind11 (2.10) would allocate one without constructing it
// and read its garbage. Every function taking one of these refuses such an object instead.
namespace pybind11::detail {
template <class T>
class constructed_caster : public type_caster_base<T> {
 public:
  bool load(handle src, bool convert) {
    tailor::python::require_constructed(src, typeid(T));
    return type_caster_base<T>::load(src, convert);
  }
};
template <>
class type_caster<tailor::python::PyMesh> : public constructed_caster<tailor::python::PyMesh> {};
template <>
class type_caster<tailor::python::PyResult> : public constructed_caster<tailor::python::PyResult> {};
template <>
class type_caster<tailor::ChunkedMapper> : public constructed_caster<tailor::ChunkedMapper> {};
}  // namespace pybind11::detail
