// PLY reader: ascii, binary_little_endian and binary_big_endian (Turk 1994, "The PLY Polygon File
// Format"). Any property order and scalar type, any list count/index type, `face` lists named
// vertex_indices or vertex_index, `tristrips` with -1 restarts, per-vertex s/t, u/v or
// texture_u/texture_v, per-vertex normals (nx ny nz) and colours (red green blue [alpha], kept as
// NORMAL and COLOR_0 corner attributes), per-face `texcoord` lists and a per-face `seam` flag;
// other elements and properties are skipped.
//
// Hand-written rather than taken from a library: the PLY parsers Debian ships (rply, the VCG and
// PCL readers, tinyply-style code) either go through a callback or a per-property dispatch for
// every value, trust header counts when allocating, or do not bounds-check binary lists. Here the
// whole file is in memory, every count is checked against the bytes left before anything is
// allocated, and the common binary layout (float x y z at fixed offsets, faces as uchar 3 +
// int/uint indices) is read by two tight loops with no per-value dispatch, at memory speed.
#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <vector>

#include "io/readers.h"
#include "util/huge_pages.h"
#include "util/saturating.h"
#include "util/text_scan.h"

namespace tailor::internal {
namespace {

// ================================================================================================
// Header model
// ================================================================================================

enum class PlyType : uint8_t { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64, kNone };

size_t type_size(PlyType t) {
  switch (t) {
    case PlyType::kInt8:
    case PlyType::kUint8: return 1;
    case PlyType::kInt16:
    case PlyType::kUint16: return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32: return 4;
    case PlyType::kFloat64: return 8;
    case PlyType::kNone: return 0;
  }
  return 0;
}

PlyType parse_type(std::string_view s) {
  if (s == "char" || s == "int8") return PlyType::kInt8;
  if (s == "uchar" || s == "uint8") return PlyType::kUint8;
  if (s == "short" || s == "int16") return PlyType::kInt16;
  if (s == "ushort" || s == "uint16") return PlyType::kUint16;
  if (s == "int" || s == "int32") return PlyType::kInt32;
  if (s == "uint" || s == "uint32") return PlyType::kUint32;
  if (s == "float" || s == "float32") return PlyType::kFloat32;
  if (s == "double" || s == "float64") return PlyType::kFloat64;
  return PlyType::kNone;
}

// What a property means to tailor; everything else is skipped.
enum class Role : uint8_t {
  kNone,
  kX,
  kY,
  kZ,
  kU,
  kV,
  kIndices,
  kTexcoord,
  kSeam,
  kNx,
  kNy,
  kNz,
  kRed,
  kGreen,
  kBlue,
  kAlpha  // kept per vertex: normals and colours
};
constexpr size_t kRoles = 16;

// A colour component's full scale by its type: 255 for (u)char, 65535 for (u)short, 1 for floats.
float colour_scale(PlyType t) {
  switch (t) {
    case PlyType::kInt8:
    case PlyType::kUint8: return 255.f;
    case PlyType::kInt16:
    case PlyType::kUint16: return 65535.f;
    case PlyType::kFloat32:
    case PlyType::kFloat64: return 1.f;
    default: return 4294967295.f;
  }
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kNone;        // scalar type, or the item type of a list
  PlyType count_type = PlyType::kNone;  // kNone: scalar property
  Role role = Role::kNone;
  bool is_list() const { return count_type != PlyType::kNone; }
};

enum class ElementKind : uint8_t { kOther, kVertex, kFace, kTristrips };

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  ElementKind kind = ElementKind::kOther;
  std::vector<PlyProperty> props;
};

enum class PlyFormat : uint8_t { kAscii, kBinaryLe, kBinaryBe };

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  size_t body_offset = 0;    // first byte after end_header's line end
  size_t header_lines = 0;   // line number of end_header (ascii bodies count lines from there)
  std::string texture_file;  // the first `comment TextureFile NAME` (MeshLab's, and tailor's writer's)
  uint32_t symmetry = 1;     // 4 with a `comment tailor symmetry 4` line (tailor map --symmetry 4)
};

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> w;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    const size_t b = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    if (i > b) w.push_back(line.substr(b, i - b));
  }
  return w;
}

// Caps on the header (untrusted): real headers are a few hundred bytes with a handful of elements.
// Past them the reader fails with one line instead of spending time and memory on the header.
constexpr size_t kMaxHeaderBytes = size_t{1} << 20;
constexpr size_t kMaxHeaderElements = 4096;
constexpr size_t kMaxHeaderProperties = 16384;

// One pass over the header lines: O(header bytes), no step looks back at earlier elements.
Status parse_header(std::string_view data, const std::string& name, PlyHeader& h) {
  size_t pos = 0, line_no = 0, property_count = 0;
  bool have_format = false;
  std::array<bool, 4> seen_kind{};  // indexed by ElementKind: vertex, face, tristrips may appear once
  // Lines are looked for only within the cap, so a file without newlines is not scanned to its end.
  const std::string_view head = data.substr(0, kMaxHeaderBytes + 1);
  for (;;) {
    if (pos >= data.size()) return Status::error(ErrorCode::kParse, name, "PLY header has no end_header line");
    size_t eol = head.find('\n', pos);
    if (eol == std::string_view::npos && data.size() > kMaxHeaderBytes) {
      return Status::error(ErrorCode::kLimit, name, "PLY header longer than 1 MiB",
                           "line " + std::to_string(line_no + 1));
    }
    const bool last = eol == std::string_view::npos;
    if (last) eol = data.size();
    std::string_view line = data.substr(pos, eol - pos);
    pos = last ? data.size() : eol + 1;
    ++line_no;
    const std::string where = "line " + std::to_string(line_no);
    const auto w = split_words(line);
    if (line_no == 1) {
      if (w.size() != 1 || w[0] != "ply")
        return Status::error(ErrorCode::kParse, name, "not a PLY file (no 'ply' magic)", where);
      continue;
    }
    if (w.size() >= 3 && w[0] == "comment" && w[1] == "TextureFile" && h.texture_file.empty()) {
      // The name is the rest of the line (it may hold blanks), trimmed.
      h.texture_file = std::string(trimmed(line.substr(line.find("TextureFile") + 11)));
      continue;
    }
    if (w.size() == 4 && w[0] == "comment" && w[1] == "tailor" && w[2] == "symmetry" && w[3] == "4") h.symmetry = 4;
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "format") {
      if (w.size() < 2) return Status::error(ErrorCode::kParse, name, "PLY format line without a format", where);
      if (w[1] == "ascii")
        h.format = PlyFormat::kAscii;
      else if (w[1] == "binary_little_endian")
        h.format = PlyFormat::kBinaryLe;
      else if (w[1] == "binary_big_endian")
        h.format = PlyFormat::kBinaryBe;
      else
        return Status::error(ErrorCode::kUnsupported, name, "unknown PLY format " + quote_input(w[1]), where);
      have_format = true;
    } else if (w[0] == "element") {
      uint64_t count = 0;
      // A count past 2^64 - 1 is out of range for from_chars, which then leaves count at 0.
      const auto parsed = w.size() == 3 ? std::from_chars(w[2].data(), w[2].data() + w[2].size(), count)
                                        : std::from_chars_result{nullptr, std::errc::invalid_argument};
      if (w.size() != 3 || parsed.ec != std::errc{} || parsed.ptr != w[2].data() + w[2].size() || w[2][0] == '-') {
        return Status::error(ErrorCode::kParse, name, "bad PLY element line", where);
      }
      PlyElement e;
      e.name = std::string(w[1]);
      e.count = count;
      if (e.name == "vertex")
        e.kind = ElementKind::kVertex;
      else if (e.name == "face")
        e.kind = ElementKind::kFace;
      else if (e.name == "tristrips")
        e.kind = ElementKind::kTristrips;
      if (e.kind != ElementKind::kOther) {
        if (seen_kind[static_cast<size_t>(e.kind)]) {
          return Status::error(ErrorCode::kUnsupported, name, "more than one PLY " + quote_input(e.name) + " element",
                               where);
        }
        seen_kind[static_cast<size_t>(e.kind)] = true;
      }
      if (h.elements.size() == kMaxHeaderElements) {
        return Status::error(ErrorCode::kLimit, name,
                             "PLY header declares more than " + std::to_string(kMaxHeaderElements) + " elements",
                             where);
      }
      h.elements.push_back(std::move(e));
    } else if (w[0] == "property") {
      if (h.elements.empty()) return Status::error(ErrorCode::kParse, name, "PLY property before any element", where);
      if (++property_count > kMaxHeaderProperties) {
        return Status::error(ErrorCode::kLimit, name,
                             "PLY header declares more than " + std::to_string(kMaxHeaderProperties) + " properties",
                             where);
      }
      PlyProperty p;
      if (w.size() == 5 && w[1] == "list") {
        p.count_type = parse_type(w[2]);
        p.type = parse_type(w[3]);
        p.name = std::string(w[4]);
        if (p.count_type == PlyType::kNone || p.type == PlyType::kNone) {
          return Status::error(ErrorCode::kParse, name, "unknown PLY list type", where);
        }
        if (p.count_type == PlyType::kFloat32 || p.count_type == PlyType::kFloat64) {
          return Status::error(ErrorCode::kParse, name, "PLY list count type must be an integer type", where);
        }
      } else if (w.size() == 3) {
        p.type = parse_type(w[1]);
        p.name = std::string(w[2]);
        if (p.type == PlyType::kNone) {
          return Status::error(ErrorCode::kParse, name, "unknown PLY property type " + quote_input(w[1]), where);
        }
      } else {
        return Status::error(ErrorCode::kParse, name, "bad PLY property line", where);
      }
      h.elements.back().props.push_back(std::move(p));
    } else if (w[0] == "end_header") {
      if (!have_format) return Status::error(ErrorCode::kParse, name, "PLY header has no format line", where);
      h.body_offset = pos;
      h.header_lines = line_no;
      return Status::ok();
    } else {
      return Status::error(ErrorCode::kParse, name, "unknown PLY header keyword " + quote_input(w[0]), where);
    }
  }
}

// Assigns roles; fails when the vertex element lacks x, y, z or the face element lacks indices.
Status assign_roles(PlyHeader& h, const std::string& name, LoadReport& report) {
  bool have_vertex = false;
  for (PlyElement& e : h.elements) {
    std::array<const PlyProperty*, kRoles> first{};  // per role: the property read for it, or none
    const auto seen = [&first](Role r) { return first[static_cast<size_t>(r)] != nullptr; };
    struct Repeat {
      const PlyProperty* property;
      Role role;
    };
    std::vector<Repeat> repeats;  // properties of a role an earlier one has: not read
    for (PlyProperty& p : e.props) {
      const std::string& n = p.name;
      Role r = Role::kNone;
      if (e.kind == ElementKind::kVertex && !p.is_list()) {
        if (n == "x")
          r = Role::kX;
        else if (n == "y")
          r = Role::kY;
        else if (n == "z")
          r = Role::kZ;
        else if (n == "s" || n == "u" || n == "texture_u" || n == "texture_s")
          r = Role::kU;
        else if (n == "t" || n == "v" || n == "texture_v" || n == "texture_t")
          r = Role::kV;
        else if (n == "nx" || n == "ny" || n == "nz")
          r = n == "nx" ? Role::kNx : n == "ny" ? Role::kNy : Role::kNz;
        else if (n == "red" || n == "r" || n == "diffuse_red")
          r = Role::kRed;
        else if (n == "green" || n == "g" || n == "diffuse_green")
          r = Role::kGreen;
        else if (n == "blue" || n == "b" || n == "diffuse_blue")
          r = Role::kBlue;
        else if (n == "alpha" || n == "a")
          r = Role::kAlpha;
      } else if (e.kind == ElementKind::kFace) {
        if (p.is_list() && (n == "vertex_indices" || n == "vertex_index"))
          r = Role::kIndices;
        else if (p.is_list() && n == "texcoord")
          r = Role::kTexcoord;
        else if (!p.is_list() && n == "seam")
          r = Role::kSeam;
      } else if (e.kind == ElementKind::kTristrips) {
        if (p.is_list() && !seen(Role::kIndices)) r = Role::kIndices;
      }
      if (r != Role::kNone) {
        if (seen(r)) {
          repeats.push_back({&p, r});  // the first one wins
          r = Role::kNone;
        } else {
          first[static_cast<size_t>(r)] = &p;
        }
      }
      p.role = r;
    }
    if (e.kind == ElementKind::kVertex) {
      have_vertex = true;
      if (!seen(Role::kX) || !seen(Role::kY) || !seen(Role::kZ)) {
        return Status::error(ErrorCode::kParse, name, "PLY vertex element has no x, y and z properties");
      }
      if (seen(Role::kU) != seen(Role::kV)) {
        for (PlyProperty& p : e.props) {
          if (p.role == Role::kU || p.role == Role::kV) p.role = Role::kNone;  // half a uv pair is no uv
        }
      }
      auto all = [&](std::initializer_list<Role> roles) { return std::all_of(roles.begin(), roles.end(), seen); };
      const bool normals = all({Role::kNx, Role::kNy, Role::kNz}),
                 colours = all({Role::kRed, Role::kGreen, Role::kBlue});
      for (PlyProperty& p : e.props) {  // part of a normal or a colour is neither
        if (!normals && (p.role == Role::kNx || p.role == Role::kNy || p.role == Role::kNz)) p.role = Role::kNone;
        if (!colours && p.role >= Role::kRed) p.role = Role::kNone;
      }
    }
    for (const Repeat& r : repeats) {
      const PlyProperty& read = *first[static_cast<size_t>(r.role)];  // unless a half pair dropped it
      add_not_read(report, "PLY " + e.name + " property " + r.property->name +
                               (read.role == r.role ? " (" + read.name + " before it is read in its place)" : ""));
    }
    if ((e.kind == ElementKind::kFace || e.kind == ElementKind::kTristrips) && !seen(Role::kIndices)) {
      return Status::error(ErrorCode::kParse, name, "PLY " + e.name + " element has no vertex_indices list");
    }
  }
  if (!have_vertex) return Status::error(ErrorCode::kParse, name, "PLY file has no vertex element");
  return Status::ok();
}

// ================================================================================================
// Value sources: binary (with or without byte swap) and ascii
// ================================================================================================

template <bool kSwap>
class BinarySource {
 public:
  BinarySource(const char* p, const char* end) : p_(p), end_(end) {}
  static constexpr bool kBinary = true;
  size_t remaining() const { return static_cast<size_t>(end_ - p_); }
  const char* pos() const { return p_; }
  void advance(size_t n) { p_ += n; }
  std::string where(const PlyElement& e, uint64_t i) const { return e.name + " " + std::to_string(i); }
  // A binary record is its properties' bytes: it always ends where they do.
  enum class RecordEnd { kEnds, kMoreValues, kSpansLines };
  RecordEnd record_ends() { return RecordEnd::kEnds; }
  std::string record_where(const PlyElement& e, uint64_t i) const { return where(e, i); }
  // Lower bound of the bytes a list of n items of type t takes.
  uint64_t list_min_bytes(uint64_t n, PlyType t) const { return mul_sat(n, type_size(t)); }

  bool value(PlyType t, double& out) {
    const size_t n = type_size(t);
    if (remaining() < n) return false;
    switch (t) {
      case PlyType::kInt8: out = static_cast<int8_t>(*p_); break;
      case PlyType::kUint8: out = static_cast<uint8_t>(*p_); break;
      case PlyType::kInt16: out = static_cast<int16_t>(load16()); break;
      case PlyType::kUint16: out = load16(); break;
      case PlyType::kInt32: out = static_cast<int32_t>(load32()); break;
      case PlyType::kUint32: out = load32(); break;
      case PlyType::kFloat32: {
        const uint32_t u = load32();
        float f;
        std::memcpy(&f, &u, 4);
        out = f;
        break;
      }
      case PlyType::kFloat64: {
        const uint64_t u = load64();
        std::memcpy(&out, &u, 8);
        break;
      }
      case PlyType::kNone: return false;
    }
    p_ += n;
    return true;
  }
  bool skip(PlyType t) {
    const size_t n = type_size(t);
    if (remaining() < n) return false;
    p_ += n;
    return true;
  }

 private:
  uint16_t load16() const {
    uint16_t u;
    std::memcpy(&u, p_, 2);
    return kSwap ? __builtin_bswap16(u) : u;
  }
  uint32_t load32() const {
    uint32_t u;
    std::memcpy(&u, p_, 4);
    return kSwap ? __builtin_bswap32(u) : u;
  }
  uint64_t load64() const {
    uint64_t u;
    std::memcpy(&u, p_, 8);
    return kSwap ? __builtin_bswap64(u) : u;
  }
  const char* p_;
  const char* end_;
};

class AsciiSource {
 public:
  AsciiSource(const char* p, const char* end, size_t first_line) : s_(p, end), first_line_(first_line) {}
  static constexpr bool kBinary = false;
  size_t remaining() const { return s_.remaining(); }
  std::string where(const PlyElement&, uint64_t) const { return "line " + std::to_string(s_.line() + first_line_); }
  // An ascii record is one line: it ends when nothing but blanks is left on the line it started
  // on (the next value read skips the line end). A record whose values ran onto the next line
  // was short of values; one whose line goes on has more than its properties.
  enum class RecordEnd { kEnds, kMoreValues, kSpansLines };
  RecordEnd record_ends() {
    const size_t started = record_line_;
    record_line_ = kNoLine;
    if (started != kNoLine && s_.line() != started) {
      record_line_ = started;  // for record_where, until the next value
      return RecordEnd::kSpansLines;
    }
    return s_.at_line_end() ? RecordEnd::kEnds : RecordEnd::kMoreValues;
  }
  std::string record_where(const PlyElement&, uint64_t) const {
    return "line " + std::to_string((record_line_ != kNoLine ? record_line_ : s_.line()) + first_line_);
  }
  // Every ascii value takes at least one character and one separator.
  uint64_t list_min_bytes(uint64_t n, PlyType) const { return n == 0 ? 0 : mul_sat(n, 2) - 1; }

  bool value(PlyType t, double& out) {
    s_.skip_space();
    if (record_line_ == kNoLine) record_line_ = s_.line();
    if (t == PlyType::kFloat32) {
      // Decimal -> float directly: decimal -> double -> float can round twice.
      float f;
      if (!s_.read_float(f)) return false;
      out = f;
      return true;
    }
    return s_.read_double(out);
  }
  bool skip(PlyType t) {
    double d;
    return value(t, d);
  }
  // After the last element: the lines left (a header that counts too few records).
  std::string rest() { return lines_after(s_, first_line_, "elements the PLY header declares"); }

 private:
  static constexpr size_t kNoLine = SIZE_MAX;
  TextScanner s_;
  size_t first_line_;
  size_t record_line_ = kNoLine;  // the line the current record's first value is on
};

// ================================================================================================
// Body reader
// ================================================================================================

bool is_index(double d) { return d >= 0.0 && d < 4294967296.0 && d == std::floor(d); }

template <class Source>
class BodyReader {
 public:
  BodyReader(Source& src, const PlyHeader& h, const std::string& name, Mesh& mesh, LoadReport& report,
             ReadProgress& progress, PolygonFans* fans)
      : src_(src),
        h_(h),
        name_(name),
        mesh_(mesh),
        report_(report),
        progress_(progress),
        fans_(fans),
        total_(src.remaining()) {
    for (const PlyElement& e : h.elements) {
      if (e.kind == ElementKind::kVertex) vertex_count_ = e.count;
    }
  }

  Status run() {
    for (const PlyElement& e : h_.elements) {
      if (!progress_.at(total_ - src_.remaining())) return progress_.cancelled(name_);
      switch (e.kind) {
        case ElementKind::kVertex: TAILOR_RETURN_IF_ERROR(read_vertices(e)); break;
        case ElementKind::kFace: TAILOR_RETURN_IF_ERROR(read_faces(e)); break;
        case ElementKind::kTristrips: TAILOR_RETURN_IF_ERROR(read_strips(e)); break;
        case ElementKind::kOther: TAILOR_RETURN_IF_ERROR(skip_element(e)); break;
      }
    }
    finish_uvs();
    if constexpr (!Source::kBinary) {
      if (const std::string rest = src_.rest(); !rest.empty()) add_not_read(report_, rest);
    }
    return Status::ok();
  }

 private:
  Status truncated(const PlyElement& e, uint64_t i) const {
    if (src_.remaining() == 0) {
      return Status::error(ErrorCode::kParse, name_, "unexpected end of file in PLY element " + quote_input(e.name),
                           src_.where(e, i));
    }
    return Status::error(ErrorCode::kParse, name_, "bad number in PLY element " + quote_input(e.name),
                         src_.where(e, i));
  }

  // The record i of e ends where its properties do (ascii: its line holds nothing more).
  Status end_record(const PlyElement& e, uint64_t i) {
    using End = typename Source::RecordEnd;
    const End end = src_.record_ends();
    if (end == End::kEnds) return Status::ok();
    return Status::error(ErrorCode::kParse, name_,
                         end == End::kMoreValues
                             ? "more values on the line than PLY element " + quote_input(e.name) + " has properties"
                             : "a record of PLY element " + quote_input(e.name) +
                                   " runs onto the next line (fewer values than its properties)",
                         src_.record_where(e, i));
  }

  // Reads a list count, checking that the items can fit in the bytes left.
  Status list_count(const PlyElement& e, uint64_t i, const PlyProperty& p, uint64_t& n) {
    double d;
    if (!src_.value(p.count_type, d)) return truncated(e, i);
    if (!is_index(d)) {
      return Status::error(ErrorCode::kParse, name_, "bad PLY list count in element " + quote_input(e.name),
                           src_.where(e, i));
    }
    n = static_cast<uint64_t>(d);
    if (src_.list_min_bytes(n, p.type) > src_.remaining()) {
      return Status::error(ErrorCode::kParse, name_,
                           "PLY list of " + std::to_string(n) + " items runs past the end of the file",
                           src_.where(e, i));
    }
    return Status::ok();
  }

  Status skip_property(const PlyElement& e, uint64_t i, const PlyProperty& p) {
    if (p.is_list()) {
      uint64_t n = 0;
      TAILOR_RETURN_IF_ERROR(list_count(e, i, p, n));
      if constexpr (Source::kBinary) {
        src_.advance(static_cast<size_t>(n * type_size(p.type)));  // checked by list_count
      } else {
        for (uint64_t k = 0; k < n; ++k) {
          if (!src_.skip(p.type)) return truncated(e, i);
        }
      }
      return Status::ok();
    }
    if (!src_.skip(p.type)) return truncated(e, i);
    return Status::ok();
  }

  Status skip_element(const PlyElement& e) {
    if (e.props.empty()) return Status::ok();
    if constexpr (Source::kBinary) {
      bool fixed = true;
      size_t stride = 0;
      for (const PlyProperty& p : e.props) {
        fixed = fixed && !p.is_list();
        stride += type_size(p.type);
      }
      if (fixed) {
        if (mul_sat(e.count, stride) > src_.remaining()) return truncated(e, src_.remaining() / stride);
        src_.advance(static_cast<size_t>(e.count * stride));
        return Status::ok();
      }
    }
    for (uint64_t i = 0; i < e.count; ++i) {
      for (const PlyProperty& p : e.props) TAILOR_RETURN_IF_ERROR(skip_property(e, i, p));
      TAILOR_RETURN_IF_ERROR(end_record(e, i));
    }
    return Status::ok();
  }

  // === Vertices =================================================================================
  Status read_vertices(const PlyElement& e) {
    // Counts were checked against the file size before this point (check_counts).
    reserve_huge(mesh_.positions, static_cast<size_t>(3 * e.count));
    mesh_.positions.resize(static_cast<size_t>(3 * e.count));
    bool have_uv = false, have_normals = false, have_colours = false;
    for (const PlyProperty& p : e.props) {
      have_uv = have_uv || p.role == Role::kU;
      have_normals = have_normals || p.role == Role::kNx;
      have_colours = have_colours || p.role == Role::kRed;
    }
    if (have_uv) vertex_uvs_.resize(static_cast<size_t>(2 * e.count));
    if (have_normals) vertex_normals_.resize(static_cast<size_t>(3 * e.count));
    if (have_colours) vertex_colours_.assign(static_cast<size_t>(4 * e.count), 1.0f);  // alpha 1 unless given
    if (!have_normals && !have_colours && fast_vertices(e, have_uv)) return Status::ok();
    float* pos = mesh_.positions.data();
    for (uint64_t i = 0; i < e.count; ++i) {
      if ((i & 0xffff) == 0 && !progress_.at(total_ - src_.remaining())) return progress_.cancelled(name_);
      for (const PlyProperty& p : e.props) {
        if (p.role == Role::kNone) {
          TAILOR_RETURN_IF_ERROR(skip_property(e, i, p));
          continue;
        }
        double d;
        if (!src_.value(p.type, d)) return truncated(e, i);
        const float f = static_cast<float>(d);
        switch (p.role) {
          case Role::kX: pos[3 * i] = f; break;
          case Role::kY: pos[3 * i + 1] = f; break;
          case Role::kZ: pos[3 * i + 2] = f; break;
          case Role::kU: vertex_uvs_[2 * i] = f; break;
          case Role::kV: vertex_uvs_[2 * i + 1] = f; break;
          case Role::kNx:
          case Role::kNy:
          case Role::kNz:
            vertex_normals_[3 * i + static_cast<size_t>(p.role) - static_cast<size_t>(Role::kNx)] = f;
            break;
          case Role::kRed:
          case Role::kGreen:
          case Role::kBlue:
          case Role::kAlpha:
            vertex_colours_[4 * i + static_cast<size_t>(p.role) - static_cast<size_t>(Role::kRed)] =
                static_cast<float>(d / colour_scale(p.type));
            break;
          default: break;
        }
      }
      TAILOR_RETURN_IF_ERROR(end_record(e, i));
    }
    return Status::ok();
  }

  // Little-endian float32 x/y/z (and u/v) at fixed offsets in a list-free element: strided copies.
  bool fast_vertices(const PlyElement& e, bool have_uv) {
    if constexpr (!Source::kBinary || std::is_same_v<Source, BinarySource<true>>) {
      return false;
    } else {
      std::array<size_t, 5> off{};  // x y z u v
      size_t stride = 0;
      for (const PlyProperty& p : e.props) {
        if (p.is_list()) return false;
        if (p.role != Role::kNone) {
          if (p.type != PlyType::kFloat32) return false;
          off[static_cast<size_t>(p.role) - static_cast<size_t>(Role::kX)] = stride;
        }
        stride += type_size(p.type);
      }
      if (mul_sat(e.count, stride) > src_.remaining()) return false;  // the generic path reports it
      const char* p = src_.pos();
      float* pos = mesh_.positions.data();
      const size_t n = static_cast<size_t>(e.count);
      for (size_t i = 0; i < n; ++i, p += stride) {
        std::memcpy(pos + 3 * i, p + off[0], 4);
        std::memcpy(pos + 3 * i + 1, p + off[1], 4);
        std::memcpy(pos + 3 * i + 2, p + off[2], 4);
      }
      if (have_uv) {
        p = src_.pos();
        float* uv = vertex_uvs_.data();
        for (size_t i = 0; i < n; ++i, p += stride) {
          std::memcpy(uv + 2 * i, p + off[3], 4);
          std::memcpy(uv + 2 * i + 1, p + off[4], 4);
        }
      }
      src_.advance(n * stride);
      return true;
    }
  }

  // === Faces ====================================================================================
  Status read_faces(const PlyElement& e) {
    // Reserve for triangles, bounded by what the remaining bytes can hold.
    const PlyProperty* ip = nullptr;
    for (const PlyProperty& p : e.props) {
      if (p.role == Role::kIndices) ip = &p;
    }
    const uint64_t tri_bytes = Source::kBinary ? type_size(ip->count_type) + 3 * type_size(ip->type) : 6;
    const uint64_t bounded = std::min<uint64_t>(e.count, src_.remaining() / tri_bytes);
    reserve_huge(mesh_.indices, mesh_.indices.size() + static_cast<size_t>(3 * bounded));
    bool have_tc = false, have_seam = false;
    for (const PlyProperty& p : e.props) {
      have_tc = have_tc || p.role == Role::kTexcoord;
      have_seam = have_seam || p.role == Role::kSeam;
    }
    if (have_tc) face_uvs_.reserve(static_cast<size_t>(6 * bounded));
    if (have_seam) seams_.reserve(static_cast<size_t>(bounded));
    face_uv_complete_ = have_tc;

    uint64_t i = 0;
    if (!have_tc && !have_seam) i = fast_faces(e);
    for (; i < e.count; ++i) {
      if ((i & 0xffff) == 0 && !progress_.at(total_ - src_.remaining())) return progress_.cancelled(name_);
      poly_.clear();
      tc_.clear();
      uint8_t seam = 0;
      for (const PlyProperty& p : e.props) {
        if (p.role == Role::kIndices) {
          TAILOR_RETURN_IF_ERROR(read_index_list(e, i, p, poly_));
        } else if (p.role == Role::kTexcoord) {
          uint64_t n = 0;
          TAILOR_RETURN_IF_ERROR(list_count(e, i, p, n));
          tc_.resize(static_cast<size_t>(n));
          for (uint64_t k = 0; k < n; ++k) {
            double d;
            if (!src_.value(p.type, d)) return truncated(e, i);
            tc_[k] = static_cast<float>(d);
          }
        } else if (p.role == Role::kSeam) {
          double d;
          if (!src_.value(p.type, d)) return truncated(e, i);
          seam = d != 0.0 ? 1 : 0;
        } else {
          TAILOR_RETURN_IF_ERROR(skip_property(e, i, p));
        }
      }
      TAILOR_RETURN_IF_ERROR(end_record(e, i));
      const size_t n = poly_.size();
      if (n < 3) {
        return Status::error(ErrorCode::kInvalidMesh, name_, "face with " + std::to_string(n) + " vertices",
                             src_.where(e, i));
      }
      if (have_tc && !tc_.empty() && tc_.size() != 2 * n) {
        return Status::error(ErrorCode::kParse, name_,
                             "texcoord list has " + std::to_string(tc_.size()) + " values for a face with " +
                                 std::to_string(n) + " vertices",
                             src_.where(e, i));
      }
      if (tc_.empty()) face_uv_complete_ = false;
      ++report_.source_faces;
      if (n > 3) ++report_.polygons_triangulated;
      if (n > 3 && fans_) fans_->add(mesh_.face_count(), n);
      for (size_t k = 1; k + 1 < n; ++k) {  // fan triangulation (concave polygons cut again: polygon_fans.h)
        mesh_.indices.insert(mesh_.indices.end(), {poly_[0], poly_[k], poly_[k + 1]});
        if (have_seam) seams_.push_back(seam);
        if (face_uv_complete_) {
          face_uvs_.insert(face_uvs_.end(),
                           {tc_[0], tc_[1], tc_[2 * k], tc_[2 * k + 1], tc_[2 * k + 2], tc_[2 * k + 3]});
        }
      }
    }
    face_triangles_ = mesh_.indices.size() / 3;
    if (have_seam) seam_triangles_ = seams_.size();
    return Status::ok();
  }

  // Reads one index list into `out`, range-checked against the vertex count.
  Status read_index_list(const PlyElement& e, uint64_t i, const PlyProperty& p, std::vector<uint32_t>& out) {
    uint64_t n = 0;
    TAILOR_RETURN_IF_ERROR(list_count(e, i, p, n));
    out.resize(static_cast<size_t>(n));
    for (uint64_t k = 0; k < n; ++k) {
      double d;
      if (!src_.value(p.type, d)) return truncated(e, i);
      if (!is_index(d) || d >= static_cast<double>(vertex_count_)) {
        return out_of_range(e, i, d);
      }
      out[k] = static_cast<uint32_t>(d);
    }
    return Status::ok();
  }

  Status out_of_range(const PlyElement& e, uint64_t i, double d) const {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", d);
    return Status::error(
        ErrorCode::kInvalidMesh, name_,
        e.name + " index " + buf + " out of range (mesh has " + std::to_string(vertex_count_) + " vertices)",
        src_.where(e, i));
  }

  // Little-endian faces made of a single uchar-counted int/uint list: copies 12 bytes per
  // triangle; returns the number of faces read (stops at the first non-triangle, which the
  // generic loop then handles).
  uint64_t fast_faces(const PlyElement& e) {
    if constexpr (!Source::kBinary || std::is_same_v<Source, BinarySource<true>>) {
      return 0;
    } else {
      if (e.props.size() != 1) return 0;
      const PlyProperty& p = e.props[0];
      if (p.count_type != PlyType::kUint8 && p.count_type != PlyType::kInt8) return 0;
      if (p.type != PlyType::kInt32 && p.type != PlyType::kUint32) return 0;
      const uint64_t n = std::min<uint64_t>(e.count, src_.remaining() / 13);
      const size_t base = mesh_.indices.size();
      mesh_.indices.resize(base + static_cast<size_t>(3 * n));
      uint32_t* out = mesh_.indices.data() + base;
      const char* q = src_.pos();
      const uint32_t nv = static_cast<uint32_t>(std::min<uint64_t>(vertex_count_, kInvalid));
      uint64_t i = 0;
      for (; i < n; ++i, q += 13) {
        if (q[0] != 3) break;
        uint32_t t[3];
        std::memcpy(t, q + 1, 12);
        // Negative int indices become >= 2^31 as uint32 and fail this test too.
        if ((t[0] >= nv) | (t[1] >= nv) | (t[2] >= nv)) break;
        std::memcpy(out + 3 * i, t, 12);
      }
      mesh_.indices.resize(base + static_cast<size_t>(3 * i));
      src_.advance(static_cast<size_t>(i * 13));
      report_.source_faces += i;
      return i;
    }
  }

  // === Triangle strips ==========================================================================
  Status read_strips(const PlyElement& e) {
    for (uint64_t i = 0; i < e.count; ++i) {
      if ((i & 0xffff) == 0 && !progress_.at(total_ - src_.remaining())) return progress_.cancelled(name_);
      for (const PlyProperty& p : e.props) {
        if (p.role != Role::kIndices) {
          TAILOR_RETURN_IF_ERROR(skip_property(e, i, p));
          continue;
        }
        uint64_t n = 0;
        TAILOR_RETURN_IF_ERROR(list_count(e, i, p, n));
        size_t run = 0;  // vertices since the last restart
        uint32_t a = 0, b = 0;
        for (uint64_t k = 0; k < n; ++k) {
          double d;
          if (!src_.value(p.type, d)) return truncated(e, i);
          if (d == -1.0) {
            run = 0;
            continue;
          }
          if (!is_index(d) || d >= static_cast<double>(vertex_count_)) return out_of_range(e, i, d);
          const uint32_t c = static_cast<uint32_t>(d);
          if (run >= 2) {
            // Odd triangles of a strip are flipped to keep a consistent winding.
            if (run % 2 == 0)
              mesh_.indices.insert(mesh_.indices.end(), {a, b, c});
            else
              mesh_.indices.insert(mesh_.indices.end(), {b, a, c});
            ++report_.source_faces;
          }
          a = b;
          b = c;
          ++run;
        }
      }
      TAILOR_RETURN_IF_ERROR(end_record(e, i));
    }
    return Status::ok();
  }

  // === Texture coordinates ======================================================================
  void finish_uvs() {
    const size_t nf = mesh_.indices.size() / 3;
    // Normals and colours per vertex become per-corner attributes (export writes them back).
    auto per_corner = [&](const std::vector<float>& values, const char* name, int k) {
      if (values.empty() || values.size() != size_t(k) * mesh_.vertex_count()) return;
      CornerAttribute& a = mesh_.corner_attributes.emplace_back(CornerAttribute{name, k, {}});
      a.values.resize(3 * nf * size_t(k));
      for (size_t c = 0; c < 3 * nf; ++c)
        std::memcpy(&a.values[size_t(k) * c], &values[size_t(k) * mesh_.indices[c]], size_t(k) * sizeof(float));
    };
    per_corner(vertex_normals_, "NORMAL", 3);
    per_corner(vertex_colours_, "COLOR_0", 4);
    if (!seams_.empty() || seam_triangles_ > 0) {
      seams_.resize(nf, 0);  // strip triangles carry no seam flag
      mesh_.seam_faces = std::move(seams_);
    }
    if (face_uv_complete_ && face_triangles_ == nf && face_uvs_.size() == 6 * nf) {
      mesh_.corner_uvs = std::move(face_uvs_);
      return;
    }
    if (!vertex_uvs_.empty() && vertex_uvs_.size() == 2 * mesh_.vertex_count()) {
      mesh_.corner_uvs.resize(6 * nf);
      for (size_t c = 0; c < 3 * nf; ++c) {
        const uint32_t v = mesh_.indices[c];
        mesh_.corner_uvs[2 * c] = vertex_uvs_[2 * v];
        mesh_.corner_uvs[2 * c + 1] = vertex_uvs_[2 * v + 1];
      }
    }
  }

  Source& src_;
  const PlyHeader& h_;
  const std::string& name_;
  Mesh& mesh_;
  LoadReport& report_;
  ReadProgress& progress_;
  PolygonFans* fans_;  // null: not recorded
  size_t total_ = 0;   // bytes of the body
  uint64_t vertex_count_ = 0;
  std::vector<uint32_t> poly_;
  std::vector<float> tc_;
  std::vector<float> vertex_uvs_;
  std::vector<float> vertex_normals_, vertex_colours_;  // #V by 3 / 4, when the file has them
  std::vector<float> face_uvs_;
  std::vector<uint8_t> seams_;
  bool face_uv_complete_ = false;
  size_t face_triangles_ = 0;
  size_t seam_triangles_ = 0;
};

// Every element needs at least count * (its smallest encoding) bytes: checked for all elements
// before anything is allocated, so a 200-byte file claiming 4e9 faces fails at once.
Status check_counts(const PlyHeader& h, size_t body_bytes, const std::string& name) {
  uint64_t need = 0;
  for (const PlyElement& e : h.elements) {
    uint64_t min_size = 0;
    for (const PlyProperty& p : e.props) {
      if (h.format == PlyFormat::kAscii)
        min_size += 2;
      else
        min_size += type_size(p.is_list() ? p.count_type : p.type);
    }
    const uint64_t bytes = mul_sat(e.count, min_size);
    need = add_sat(need, h.format == PlyFormat::kAscii && bytes > 0 ? bytes - 1 : bytes);
    if (need > body_bytes) {
      return Status::error(ErrorCode::kParse, name,
                           "PLY header declares " + std::to_string(e.count) + " " + quote_input(e.name) +
                               " elements, more than the file can hold (" + std::to_string(body_bytes) +
                               " bytes of data)");
    }
  }
  for (const PlyElement& e : h.elements) {
    if (e.kind == ElementKind::kVertex && e.count > kMaxVertices) {
      return Status::error(ErrorCode::kLimit, name, "too many vertices (" + std::to_string(e.count) + ")");
    }
    if (e.kind == ElementKind::kFace && e.count > kMaxFaces) {
      return Status::error(ErrorCode::kLimit, name, "too many faces (" + std::to_string(e.count) + ")");
    }
  }
  return Status::ok();
}

}  // namespace

Status read_ply(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report,
                ReadProgress* progress, std::string* texture_file, PolygonFans* fans) {
  ReadProgress none;
  ReadProgress& p = progress ? *progress : none;
  const std::string_view text(data.data(), data.size());
  PlyHeader h;
  TAILOR_RETURN_IF_ERROR(parse_header(text, name, h));
  if (texture_file) *texture_file = h.texture_file;
  report.texture_symmetry = h.symmetry;
  TAILOR_RETURN_IF_ERROR(assign_roles(h, name, report));
  const char* body = data.data() + h.body_offset;
  const char* end = data.data() + data.size();
  TAILOR_RETURN_IF_ERROR(check_counts(h, static_cast<size_t>(end - body), name));
  switch (h.format) {
    case PlyFormat::kAscii: {
      report.format = "PLY ascii";
      AsciiSource src(body, end, h.header_lines);
      return BodyReader<AsciiSource>(src, h, name, mesh, report, p, fans).run();
    }
    case PlyFormat::kBinaryLe: {
      report.format = "PLY binary_little_endian";
      if constexpr (std::endian::native == std::endian::little) {
        BinarySource<false> src(body, end);
        return BodyReader<BinarySource<false>>(src, h, name, mesh, report, p, fans).run();
      } else {
        BinarySource<true> src(body, end);
        return BodyReader<BinarySource<true>>(src, h, name, mesh, report, p, fans).run();
      }
    }
    case PlyFormat::kBinaryBe: {
      report.format = "PLY binary_big_endian";
      if constexpr (std::endian::native == std::endian::big) {
        BinarySource<false> src(body, end);
        return BodyReader<BinarySource<false>>(src, h, name, mesh, report, p, fans).run();
      } else {
        BinarySource<true> src(body, end);
        return BodyReader<BinarySource<true>>(src, h, name, mesh, report, p, fans).run();
      }
    }
  }
  return Status::error(ErrorCode::kParse, name, "unknown PLY format");
}

}  // namespace tailor::internal
