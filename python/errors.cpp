// tailor.Error and the small helpers every binding uses (paths, JSON, array descriptions).
#include <limits>

#include "bindings.h"

namespace tailor::python {
namespace {
// Set once by bind_errors; the module object keeps the exception type alive.
PyObject* error_type = nullptr;

const char* code_name(ErrorCode code) {
  switch (code) {
    case ErrorCode::kOk: return "ok";
    case ErrorCode::kIo: return "io";
    case ErrorCode::kParse: return "parse";
    case ErrorCode::kInvalidMesh: return "invalid_mesh";
    case ErrorCode::kInvalidImage: return "invalid_image";
    case ErrorCode::kUnsupported: return "unsupported";
    case ErrorCode::kLimit: return "limit";
    case ErrorCode::kInvalidArgument: return "invalid_argument";
    case ErrorCode::kCancelled: return "cancelled";
  }
  return "error";
}

[[noreturn]] void raise_with_code(const std::string& message, const char* code) {
  py::object error = py::reinterpret_borrow<py::object>(error_type)(utf8_text(message));
  error.attr("code") = code;
  PyErr_SetObject(error_type, error.ptr());
  throw py::error_already_set();
}
}  // namespace

void raise_status(const Status& status) { raise_with_code(status.message(), code_name(status.code())); }

void raise_error(const std::string& what) { raise_with_code(what, code_name(ErrorCode::kInvalidArgument)); }

void require_constructed(py::handle src, const std::type_info& type) {
  const py::detail::type_info* info = py::detail::get_type_info(type);
  if (info == nullptr || !src || !PyObject_TypeCheck(src.ptr(), info->type)) return;  // not ours: the caster says no
  auto* instance = reinterpret_cast<py::detail::instance*>(src.ptr());
  const auto holder = instance->get_value_and_holder(info, false);
  // Constructed: a value, and a holder unless the object only refers to one it does not own.
  if (holder && holder.value_ptr() != nullptr && (holder.holder_constructed() || !instance->owned)) return;
  const char* how = type == typeid(PyMesh)     ? "tailor.Mesh was made by __new__ without __init__: make one with "
                                                 "tailor.Mesh(positions, faces) or tailor.load(path)"
                    : type == typeid(PyResult) ? "tailor.Result was made by __new__: tailor.map returns one"
                                               : "tailor.ChunkedMapper was made by __new__ without __init__: make one "
                                                 "with tailor.ChunkedMapper(cell_exponent, texels_per_unit)";
  raise_error(how);
}

std::optional<py::array> as_array(const py::handle& o) {
  if (py::isinstance<py::array>(o)) return py::reinterpret_borrow<py::array>(o);
  try {
    return py::module_::import("numpy").attr("asarray")(o).cast<py::array>();
  } catch (py::error_already_set& e) {
    // What stops the program rather than the conversion passes through: Ctrl-C in an __array__,
    // SystemExit, running out of memory.
    if (!e.matches(PyExc_Exception) || e.matches(PyExc_MemoryError)) throw;
    return std::nullopt;
  }
}

bool whole_value(const py::handle& value, long long& out) {
  const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!index) {
    PyErr_Clear();
    return false;
  }
  int overflow = 0;
  out = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (out == -1 && PyErr_Occurred()) {
    PyErr_Clear();
    return false;
  }
  if (overflow != 0) out = overflow > 0 ? std::numeric_limits<long long>::max() : std::numeric_limits<long long>::min();
  return true;
}

int64_t whole_number(const py::handle& value, const std::string& name, int64_t lo, int64_t hi) {
  long long v = 0;
  if (!whole_value(value, v) || v < lo || v > hi)  // saturated beyond 64 bits: out of every range asked
    raise_error(name + " must be a whole number in " + std::to_string(lo) + ".." + std::to_string(hi) + ", got " +
                py::repr(value).cast<std::string>());
  return v;
}

uint32_t bounded_whole_number(const py::handle& value, const std::string& name, std::string_view flag) {
  const int64_t v = whole_number(value, name, std::numeric_limits<int64_t>::min(), std::numeric_limits<int64_t>::max());
  if (const Status s = check_option_range(flag, static_cast<double>(v)); !s) raise_status(s);
  return static_cast<uint32_t>(v);
}

std::string describe(const py::array& array) {
  std::string text = py::str(array.dtype()).cast<std::string>() + " (";
  for (py::ssize_t i = 0; i < array.ndim(); ++i) text += (i ? ", " : "") + std::to_string(array.shape(i));
  return text + (array.ndim() == 1 ? ",)" : ")");
}

std::string sequence_text(const py::handle& value) {
  if (py::isinstance<py::str>(value) || !py::isinstance<py::sequence>(value)) return py::str(value).cast<std::string>();
  std::string text;
  for (const py::handle item : value.cast<py::sequence>())
    text += (text.empty() ? "" : ",") + py::str(item).cast<std::string>();
  return text;
}

void set_chunk_split(const py::object& chunk_split, uint32_t& split_above) {
  if (chunk_split.is_none()) return;
  const int64_t n = whole_number(chunk_split, "chunk_split", 0, 0xffffffffLL);
  split_above = static_cast<uint32_t>(n);
}

std::string path_of(const py::handle& path) {
  if (!py::isinstance<py::str>(path) && !py::hasattr(path, "__fspath__"))
    raise_error("expected a path (str or os.PathLike), got " + py::str(py::type::of(path)).cast<std::string>());
  // The file system's bytes (os.fsencode): a name that is not UTF-8 (decoded by Python with
  // surrogate escapes) names the same file, where a UTF-8 cast of the str would fail.
  std::string bytes = py::module_::import("os").attr("fsencode")(path).cast<py::bytes>().cast<std::string>();
  // An empty path (texture=os.environ.get("TEX", "") with TEX unset) would read as the argument
  // left out where it is optional, and the call would go on without what was asked for.
  if (bytes.empty()) raise_error("expected a path, got an empty one");
  // The C library stops at a NUL: "a\0.glb" would write "a". Python's own open() refuses it too.
  if (bytes.find('\0') != std::string::npos)
    raise_error("path contains a NUL character: " + py::repr(path).cast<std::string>());
  return bytes;
}

py::object utf8_text(const std::string& text) {
  const py::object decoded =
      py::reinterpret_steal<py::object>(PyUnicode_DecodeUTF8(text.data(), py::ssize_t(text.size()), "replace"));
  if (!decoded) throw py::error_already_set();
  return decoded;
}

void warn(const std::string& text) {
  // Valid UTF-8 first: PyErr_WarnEx decodes its message strictly.
  if (PyErr_WarnEx(PyExc_UserWarning, PyUnicode_AsUTF8(utf8_text(text).ptr()), 1) != 0) throw py::error_already_set();
}

py::object path_text(const std::string& path) {
  return py::reinterpret_steal<py::object>(PyUnicode_DecodeFSDefaultAndSize(path.data(), py::ssize_t(path.size())));
}

py::object json_to_dict(const std::string& text) { return py::module_::import("json").attr("loads")(text); }

void bind_errors(py::module_& m) {
  static py::exception<std::exception> type(m, "Error", PyExc_ValueError);
  error_type = type.ptr();
  type.doc() =
      "Raised by every tailor call on bad input, bad options or failed I/O. str(error) is the line the "
      "tailor command prints after 'tailor: error: ' (file: what (where)); error.code names the kind: "
      "io, parse, invalid_mesh, invalid_image, unsupported, limit, invalid_argument or cancelled.";
  // An Error raised by Python code (a caller's own, or tailor.tiles') has the class's code until
  // it is given one.
  type.attr("code") = "error";
}

}  // namespace tailor::python
