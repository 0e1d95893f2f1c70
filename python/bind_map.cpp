// tailor.map and tailor.Result: the pipeline of `tailor map` (options checked and completed by
// the library's check_map_options / set_map_texture_size, --axis auto by choose_orientation_axis,
// map_texture, the report by add_map_results / map_report_json), without the files.
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <span>
#include <string>

#include "bindings.h"
#include "tailor/axis_choice.h"
#include "tailor/export.h"
#include "tailor/image.h"
#include "tailor/map_warnings.h"
#include "tailor/mapping.h"
#include "tailor/material.h"
#include "tailor/report.h"
#include "tailor/texture_direction.h"
#include "tailor/topology.h"

namespace tailor::python {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// axis: "pca", "skeleton", "x", "y", "z", "auto" or three numbers; sets the orientation and returns the text the
// report shows (as `tailor map --axis` writes it).
std::string set_axis(const py::object& axis, OrientationOptions& orientation, bool& automatic) {
  automatic = false;
  if (py::isinstance<py::str>(axis)) {
    const std::string text = axis.cast<std::string>();
    if (text == "auto") {
      automatic = true;
      return text;
    }
    if (text == "pca") {
      orientation.axis = AxisSource::kPca;
      return text;
    }
    if (text == "skeleton") {
      orientation.axis = AxisSource::kSkeleton;
      return text;
    }
    orientation.axis = AxisSource::kUser;
    if (text == "x")
      orientation.user_axis = {1, 0, 0};
    else if (text == "y")
      orientation.user_axis = {0, 1, 0};
    else if (text == "z")
      orientation.user_axis = {0, 0, 1};
    else
      raise_error("--axis must be auto, pca, skeleton, x, y, z or three numbers X,Y,Z, got '" + text + "'");
    return text;
  }
  std::array<float, 3> v{};
  try {
    const auto values = axis.cast<std::vector<double>>();
    if (values.size() != 3) throw py::cast_error();
    for (size_t i = 0; i < 3; ++i) v[i] = static_cast<float>(values[i]);
  } catch (const py::cast_error&) {
    raise_error("--axis must be auto, pca, skeleton, x, y, z or three numbers X,Y,Z, got '" + sequence_text(axis) +
                "'");
  }
  if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
    raise_error("--axis must be auto, pca, skeleton, x, y, z or three numbers X,Y,Z, got '" + sequence_text(axis) +
                "'");
  orientation.axis = AxisSource::kUser;
  orientation.user_axis = v;
  char text[64];
  std::snprintf(text, sizeof text, "%g,%g,%g", v[0], v[1], v[2]);
  return text;
}

// seam_faces: a boolean mask (F,) or face indices (any integer dtype) -> #F flags.
void seam_flags(const py::array& seams, size_t face_count, std::vector<uint8_t>& flags) {
  flags.assign(face_count, 0);
  if (seams.ndim() != 1)
    raise_error("seam_faces must be a 1-D array of face indices or an (F,) bool mask, got " + describe(seams));
  if (seams.dtype().kind() == 'b') {
    if (static_cast<size_t>(seams.shape(0)) != face_count)
      raise_error("seam_faces as a mask must have one entry per face (" + std::to_string(face_count) + "), got " +
                  describe(seams));
    const auto mask = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(seams);
    for (size_t f = 0; f < face_count; ++f) flags[f] = mask.data()[f] ? 1 : 0;
    return;
  }
  if (seams.shape(0) == 0) return;  // no index: [] is float64 to numpy, and means no seam face
  if (seams.dtype().kind() != 'i' && seams.dtype().kind() != 'u')
    raise_error("seam_faces must hold integer face indices or bools, got " + describe(seams));
  const auto ids = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(seams);
  for (py::ssize_t i = 0; i < ids.shape(0); ++i) {
    const int64_t f = ids.data()[i];
    if (f < 0 || static_cast<uint64_t>(f) >= face_count)
      raise_error("seam face index " + std::to_string(f) + " out of range (mesh has " + std::to_string(face_count) +
                  " faces) (entry " + std::to_string(i) + ")");
    flags[static_cast<size_t>(f)] = 1;
  }
}

// map()'s docstring: the call, then every option with the CLI's help text, from the library's
// OptionDoc tables (the keyword is the field's name, threshold_px and smooth_passes shortened).
const std::string& map_docstring() {
  static const std::string text = [] {
    std::string doc =
        "map(mesh, texture_size=512, scale=800.0, axis='pca', seam_faces=None, threads=0, progress=None, *, ...) "
        "-> Result\n\n"
        "Computes per-corner texture coordinates by homogeneous patch discovery, exactly as `tailor map` (same\n"
        "options, same bits; the GIL is released while it works). Raises tailor.Error with the CLI's message on\n"
        "bad options.\n\n"
        "texture_size: pixels of one texture repeat (--texture-size); texture=PATH sets it from the image (--texture)\n"
        "material: a PBR material instead of texture (--material): a folder of maps named *_color, *_normal,\n"
        "  *_roughness, *_metallic, *_ao, *_height..., or a JSON naming them; its colour map (else its first\n"
        "  map) sets the texture size and field_following 'auto'; tailor.save embeds it in a .glb; the\n"
        "  quarter-turn tiles of `tailor tile --set --symmetry 4` (its material.json) are mapped with symmetry 4\n"
        "symmetry: None (default) = 1, or the material's 4 as above; 1 or 4 as --symmetry\n"
        "axis: 'pca', 'x', 'y', 'z', 'auto' or three numbers\n"
        "seam_faces: face indices or an (F,) bool mask of faces where seams should go; None: the file's PLY\n"
        "  `seam` property, if any\n"
        "threads: 0 = automatic (--threads); the result is the same for any count\n"
        "progress: callable(fraction), called every 50 ms or so and with 1.0 at the end; return False to stop\n"
        "  (tailor.Error 'mapping cancelled'); an exception it raises propagates. Ctrl-C stops the map\n"
        "  (KeyboardInterrupt) with or without it.\n"
        "field_following: 'auto' (default) as the CLI: 0 with 32 crack rings when texture= has no direction\n"
        "  (gravel, grass), else 1; crack_rings: None = 16, or auto's choice\n"
        "unit_scale: 0 normalises the mesh into the unit cube (as the CLI); > 0 uses coordinates times unit_scale,\n"
        "  so with unit_scale=1, scale is pixels per mesh unit: one texel density on every mesh (no CLI flag)\n"
        "chunks: 'auto', 'on' or 'off' (--chunks); chunk_cell: None = auto, or the cell side's power of two\n"
        "  (--chunk-cell); chunk_split: None = 131072, or 0 (never cut) or at least 64 (--chunk-split)\n\n"
        "The options with the CLI's help (tailor map --help):\n";
    auto add = [&doc](std::span<const OptionDoc> docs) {
      for (const OptionDoc& d : docs) {
        std::string name(d.field);
        if (name == "strokes") continue;  // not a keyword of map() (yet): tailor map --strokes only
        if (name == "threshold_px") name = "threshold";
        if (name == "smooth_passes") name = "smooth";
        if (name == "shorten_seams" || name == "close_cracks") name += "=False";
        doc += name + " (" + std::string(d.flag) + "): " + help_with_range(d) + "\n";
      }
    };
    add(kMappingOptionDocs);
    add(kOrientationOptionDocs);
    for (const OptionDoc& d : kChunkOptionDocs) {
      const std::string_view field = d.field;
      const char* name = field == "mode" ? "chunks" : field == "split_above" ? "chunk_split" : "chunk_cell";
      doc += "  " + std::string(d.flag) + " (" + name + "): " + std::string(d.help) + "\n";
    }
    return doc;
  }();
  return text;
}

// An image file decoded as tailor map reads a texture, without the GIL (tailor.Error when it
// cannot be).
Image read_image(const py::object& file) {
  const std::string path = path_of(file);  // with the GIL: it reads a Python object
  Image image;
  Status s;
  {
    const py::gil_scoped_release release;
    s = load_image(path, image);
  }
  if (!s) raise_status(s);
  return image;
}

}  // namespace

void bind_map(py::module_& m) {
  py::class_<PyResult>(m, "Result", "What tailor.map returns: the UVs, the patches and the reports.")
      .def_property_readonly(
          "corner_uvs",
          [](py::object self) {
            const PyResult& r = self.cast<const PyResult&>();
            return readonly_view(r.corner_uvs.data(), {py::ssize_t(r.atlas.patch.size()), 3, 2}, self);
          },
          "(F, 3, 2) float32: per-corner UVs in texture repeats (1.0 = one texture width), v up (OBJ "
          "convention), bit for bit what `tailor map` writes")
      .def_property_readonly(
          "patch",
          [](py::object self) {
            const PyResult& r = self.cast<const PyResult&>();
            return readonly_view(r.atlas.patch.data(), {py::ssize_t(r.atlas.patch.size())}, self);
          },
          "(F,) uint32: the patch of every face")
      .def_property_readonly(
          "patch_count", [](const PyResult& r) { return r.atlas.patch_count; }, "number of patches")
      .def_property_readonly(
          "texture_size", [](const PyResult& r) { return py::make_tuple(r.texture_width, r.texture_height); },
          "(width, height) in pixels of one texture repeat")
      .def_property_readonly(
          "stats", [](const PyResult& r) { return r.stats; },
          "dict: the JSON report of `tailor map --stats` (options, mesh, mapping, metrics, time_ms)")
      .def_property_readonly(
          "metrics", [](const PyResult& r) { return r.stats["metrics"]; },
          "dict: the quality metrics (stats['metrics']: seam_length_ratio, flipped, stretch, l2_stretch, ...)")
      .def_property_readonly(
          "library_seconds", [](const PyResult& r) { return r.library_seconds; },
          "seconds spent in the library's calls (topology, axis choice, map_texture, report): what the "
          "same C++ calls take; the rest of the call's time is the binding's")
      .def("__repr__", [](const PyResult& r) {
        return "<tailor.Result " + std::to_string(r.atlas.patch.size()) + " faces, " +
               std::to_string(r.atlas.patch_count) + " patches>";
      });

  const MappingOptions md;  // the library's defaults, shown in the signature
  m.def(
      "map",
      [](const PyMesh& mesh, int texture_size, float scale, const py::object& axis, const py::object& seam_faces,
         uint32_t threads, const py::object& progress, const py::object& texture, const std::string& mode,
         float max_stretch, const py::object& field_following, uint32_t min_patch_faces, float hop_age,
         bool shorten_seams, bool close_cracks, const py::object& crack_rings, uint32_t relax_iterations,
         float threshold, const py::object& seed_point, const py::object& symmetry, float unit_scale, uint32_t smooth,
         const py::object& material, const std::string& chunks, const py::object& chunk_cell,
         const py::object& chunk_split) {
        // === Options, checked before any work (the CLI's checks and messages) ===
        MapTextureOptions options;
        MappingOptions& mapping = options.mapping;
        MapRun run;
        run.input = mesh.source;
        run.axis = set_axis(axis, options.orientation, run.axis_auto);
        if (!mapping_mode_from_name(mode, mapping.mode))
          raise_error("--mode must be patches or thesis, got '" + mode + "'");
        mapping.scale = scale;
        mapping.max_stretch = max_stretch;
        // 'auto' (the CLI's default): decided by the texture below, as --field-following auto.
        const bool field_following_auto =
            py::isinstance<py::str>(field_following) && field_following.cast<std::string>() == "auto";
        if (!field_following_auto) {
          float value = -1.f;
          if (!py::isinstance<py::str>(field_following)) {
            try {
              value = field_following.cast<float>();
            } catch (const py::cast_error&) {
            }
          }
          if (!(value >= 0.f && value <= 1.f))
            raise_error("--field-following must be auto or a number in [0, 1], got '" +
                        py::str(field_following).cast<std::string>() + "'");
          mapping.field_following = value;
        }
        run.field_following_auto = field_following_auto;
        mapping.min_patch_faces = min_patch_faces;
        mapping.hop_age = hop_age;
        mapping.shorten_seams = shorten_seams;
        mapping.close_cracks = close_cracks;
        if (!crack_rings.is_none())  // else as auto decides
          mapping.crack_rings = bounded_whole_number(crack_rings, "crack_rings", "--crack-rings");
        mapping.relax_iterations = relax_iterations;
        mapping.threshold_px = threshold;
        if (!symmetry.is_none()) {
          int value = 0;
          try {
            value = symmetry.cast<int>();
          } catch (const py::cast_error&) {
          }
          if (value != 1 && value != 4)
            raise_error("--symmetry: " + py::str(symmetry).cast<std::string>() + " not in {1,4}");
          mapping.symmetry = static_cast<uint32_t>(value);
        }
        if (threads > 64) raise_error("--threads: value " + std::to_string(threads) + " not in range [0 - 64]");
        mapping.threads = threads;
        if (!seed_point.is_none()) {
          std::vector<double> p;
          try {
            p = seed_point.cast<std::vector<double>>();
          } catch (const py::cast_error&) {
          }
          if (p.size() != 3 || !std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
            raise_error("--seed-point must be three numbers X,Y,Z, got '" + sequence_text(seed_point) + "'");
          mapping.seed_point = {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])};
          mapping.use_seed_point = true;
          char text[96];
          std::snprintf(text, sizeof text, "%g,%g,%g", p[0], p[1], p[2]);
          run.seed_point = text;
        }
        if (!(unit_scale >= 0.f && unit_scale <= 1e30f)) raise_error("unit_scale must be 0 or a positive number");
        options.orientation.fixed_unit_scale = unit_scale;  // about the origin (fixed_origin stays 0, 0, 0)
        if (chunks == "auto")
          options.chunks.mode = ChunkMode::kAuto;
        else if (chunks == "on")
          options.chunks.mode = ChunkMode::kOn;
        else if (chunks == "off")
          options.chunks.mode = ChunkMode::kOff;
        else
          raise_error("chunks must be 'auto', 'on' or 'off', got '" + chunks + "'");
        if (!chunk_cell.is_none()) {
          const int e = static_cast<int>(whole_number(chunk_cell, "chunk_cell", -60, 60));
          options.chunks.cell_exponent = e;
        }
        set_chunk_split(chunk_split, options.chunks.split_above);
        options.orientation.smooth_passes = smooth;
        if (Status s = check_texture_size(texture_size); !s) raise_status(s);
        if (Status s = check_map_options(options); !s) raise_status(s);
        // A keyword the mode does not read, away from its default, would be taken and do nothing.
        const MappingOptions unset;
        const auto differs = [&](std::string_view key) {
          if (key == "max_stretch") return mapping.max_stretch != unset.max_stretch;
          if (key == "field_following") return !field_following_auto;
          if (key == "min_patch_faces") return mapping.min_patch_faces != unset.min_patch_faces;
          if (key == "hop_age") return mapping.hop_age != unset.hop_age;
          if (key == "shorten_seams") return !mapping.shorten_seams;
          if (key == "close_cracks") return !mapping.close_cracks;
          if (key == "crack_rings") return !crack_rings.is_none();
          if (key == "relax_iterations") return mapping.relax_iterations != unset.relax_iterations;
          raise_error("internal: map() does not check the patches-mode option '" + std::string(key) + "'");
        };
        std::string_view given;
        for (const OptionDoc* doc : kPatchesOnlyOptions)
          if (differs(doc->field) && given.empty()) given = doc->flag;
        if (Status s = check_mode_options(mapping.mode, given, mapping.threshold_px != unset.threshold_px); !s)
          raise_status(s);
        // The texture sets the texture size, as --texture does; a material's colour map (else its
        // maps' size), as --material does.
        int width = texture_size, height = texture_size;
        Image image;
        std::string material_path;
        if (!material.is_none()) {
          if (!texture.is_none())
            raise_error("give --texture or --material, not both (the material's colour map is the texture)");
          material_path = path_of(material);
          MaterialMaps maps;
          Status s;
          {
            const py::gil_scoped_release release;
            s = load_material(material_path, maps);
          }
          if (!s) raise_status(s);
          for (const std::string& note : maps.notes) warn(note);
          run.texture = maps.color;
          // Quarter-turn tiles (`tailor tile --set --symmetry 4`) are mapped for them unless told.
          if (maps.symmetry == 4 && symmetry.is_none() && mapping.mode == MappingMode::kPatches) mapping.symmetry = 4;
          width = maps.width;
          height = maps.height;
        } else if (!texture.is_none()) {
          run.texture = path_of(texture);
        }
        if (!run.texture.empty()) {
          Status s;
          {
            const py::gil_scoped_release release;
            s = load_image(run.texture, image);
          }
          if (!s) raise_status(s);
          width = image.width;
          height = image.height;
        }
        if (field_following_auto)
          run.texture_isotropy = adapt_mapping_to_texture(image, mapping, !crack_rings.is_none());
        if (Status s = set_map_texture_size(options, width, height); !s) raise_status(s);
        // Symmetry 4 under a texture that is not a 4-fold tile, or repeating less than once: what
        // `tailor map` prints, as UserWarning (an error where the warnings filter says so).
        for (const std::string& line : map_warnings(mesh.mesh, options, image, run.texture)) warn(line);
        std::vector<uint8_t> seams;
        if (!seam_faces.is_none()) {
          const std::optional<py::array> seam_array = as_array(seam_faces);
          if (!seam_array) raise_error("seam_faces must be face indices or an (F,) bool mask");
          seam_flags(*seam_array, mesh.mesh.face_count(), seams);
          mapping.seam_faces = seams;
        } else if (!mesh.mesh.seam_faces.empty()) {
          mapping.seam_faces = mesh.mesh.seam_faces;
        }
        run.texture_width = width;
        run.texture_height = height;

        // === The work, without the GIL ===
        auto result = std::make_unique<PyResult>();
        result->texture_width = width;
        result->texture_height = height;
        result->texture = run.texture;
        result->material = material_path;
        result->symmetry = mapping.symmetry;
        ProgressBridge bridge(progress);
        const auto report_progress = bridge.function();
        Status status;
        std::string stats;
        {
          const py::gil_scoped_release release;
          const auto start = std::chrono::steady_clock::now();
          // As `tailor map`: the topology serves the axis choice and the metrics, so unless the axis
          // is chosen it is built after the mapping (less memory at the mapping's peak, and progress
          // reports, hence Ctrl-C, from the start).
          Topology topology;
          if (run.axis_auto) {
            topology = build_topology(mesh.mesh, {}, options.mapping.threads);
            const auto axis_start = std::chrono::steady_clock::now();
            // One range for the callback: the axis choice its first half, the mapping the second.
            mapping.progress = [&report_progress](float f) { return report_progress(0.5f * f); };
            AxisChoice choice;
            status = choose_orientation_axis(mesh.mesh, topology, options, choice);
            if (status) {
              run.axis_choice_seconds = seconds_since(axis_start);
              options.orientation = orientation_for(choice.best, options.orientation);
              run.axis = std::string("auto:") + axis_candidate_name(choice.best);
            }
          }
          TextureMap map;
          if (status) {
            mapping.progress = [&report_progress, half = run.axis_auto](float f) {
              return report_progress(half ? 0.5f + 0.5f * f : f);
            };
            MapTextureOptions unmeasured = options;
            unmeasured.measure = false;
            status = map_texture(mesh.mesh, topology, unmeasured, map);
          }
          if (status) {
            if (topology.opposite.empty()) topology = build_topology(mesh.mesh, {}, options.mapping.threads);
            status = measure_texture_map(mesh.mesh, topology, options, map);
          }
          if (status) {
            run.options = options;
            add_map_results(mesh.mesh, mesh.load, topology, map, run);
            run.total_seconds = seconds_since(start);
            stats = map_report_json(run);
            result->library_seconds = seconds_since(start);
            // Pixels -> repeats, as export_mesh writes them (double scale, rounded once to float).
            const double su = 1.0 / width, sv = 1.0 / height;
            const std::vector<float>& px = map.atlas.corner_uv;
            result->corner_uvs.resize(px.size());
            for (size_t i = 0; i < px.size(); i += 2) {
              result->corner_uvs[i] = static_cast<float>(px[i] * su);
              result->corner_uvs[i + 1] = static_cast<float>(px[i + 1] * sv);
            }
            result->atlas = std::move(map.atlas);
          }
        }
        bridge.finish(status.with_file(mesh.source));
        result->stats = json_to_dict(stats);
        return result;
      },
      py::arg("mesh"), py::arg("texture_size") = ExportOptions{}.texture_width, py::arg("scale") = md.scale,
      py::arg("axis") = "pca", py::arg("seam_faces") = py::none(), py::arg("threads") = md.threads,
      py::arg("progress") = py::none(), py::kw_only(), py::arg("texture") = py::none(),
      py::arg("mode") = mapping_mode_name(md.mode), py::arg("max_stretch") = md.max_stretch,
      py::arg("field_following") = "auto", py::arg("min_patch_faces") = md.min_patch_faces,
      py::arg("hop_age") = md.hop_age, py::arg("shorten_seams") = md.shorten_seams,
      py::arg("close_cracks") = md.close_cracks, py::arg("crack_rings") = py::none(),
      py::arg("relax_iterations") = md.relax_iterations, py::arg("threshold") = md.threshold_px,
      py::arg("seed_point") = py::none(), py::arg("symmetry") = py::none(),
      py::arg("unit_scale") = OrientationOptions{}.fixed_unit_scale,
      py::arg("smooth") = OrientationOptions{}.smooth_passes, py::arg("material") = py::none(),
      py::arg("chunks") = "auto", py::arg("chunk_cell") = py::none(), py::arg("chunk_split") = py::none(),
      map_docstring().c_str());
  // The same defaults by name, for what takes map()'s options another way (tailor.tiles' flags).
  py::dict defaults;
  defaults["texture_size"] = ExportOptions{}.texture_width;
  defaults["scale"] = md.scale;
  defaults["max_stretch"] = md.max_stretch;
  defaults["crack_rings"] = md.crack_rings;
  m.attr("MAP_DEFAULTS") = defaults;
  // Their ranges (MappingLimits, OrientationLimits), (lowest, highest), which map() and tailor.tiles check against.
  using L = MappingLimits;
  py::dict limits;
  limits["scale"] = py::make_tuple(L::min_scale, L::max_scale);
  limits["max_stretch"] = py::make_tuple(L::min_max_stretch, L::max_max_stretch);
  limits["hop_age"] = py::make_tuple(0.f, L::max_hop_age);
  limits["crack_rings"] = py::make_tuple(L::min_crack_rings, L::max_crack_rings);
  limits["relax_iterations"] = py::make_tuple(0u, L::max_relax_iterations);
  limits["smooth"] = py::make_tuple(0u, OrientationLimits::max_smooth_passes);
  m.attr("MAP_LIMITS") = limits;
  m.def("_range_text", &option_range_text, py::arg("flag"),
        "_range_text(flag) -> str\n\nThe range of `flag` as tailor map --help writes it, or '' (for python3 -m "
        "tailor.tiles --help).");
  m.def(
      "_range_error",
      [](const std::string& flag, double value) {
        const Status s = check_option_range(flag, value);
        return s ? std::string() : s.message();
      },
      py::arg("flag"), py::arg("value"),
      "_range_error(flag, value) -> str\n\nThe message tailor map gives for `value` outside the range of `flag` "
      "(--max-stretch, --crack-rings...), or '' (for python3 -m tailor.tiles).");

  m.def(
      "auto_field_following",
      [](const py::object& texture) {
        const Image image = read_image(texture);
        MappingOptions mapping;
        {
          const py::gil_scoped_release release;
          adapt_mapping_to_texture(image, mapping);
        }
        return py::make_tuple(mapping.field_following, mapping.crack_rings);
      },
      py::arg("texture"),
      "auto_field_following(texture) -> (field_following, crack_rings)\n\n"
      "What field_following='auto' (tailor.map, tailor map) picks for a texture: (0.0, 32) for one\n"
      "without a direction (gravel, grass), else (1.0, 16). For callers that set the options\n"
      "themselves (ChunkedMapper).");
  m.def(
      "image_size",
      [](const py::object& texture) {
        const Image image = read_image(texture);
        return py::make_tuple(image.width, image.height);
      },
      py::arg("texture"),
      "image_size(texture) -> (width, height)\n\n"
      "The size of an image file, decoded whole as tailor map reads a texture: tailor.Error when it\n"
      "cannot be (missing, truncated or corrupt, too large). For callers that name a texture\n"
      "without mapping with it.");
  m.def(
      "_texture_look",
      [](const py::object& texture, const std::string& name, bool direction) {
        const Image image = read_image(texture);
        MappingOptions mapping;
        std::string warning;
        {
          const py::gil_scoped_release release;
          warning = texture_wrap_warning(image, name);
          if (direction) adapt_mapping_to_texture(image, mapping);
        }
        if (!direction) return py::make_tuple(image.width, image.height, utf8_text(warning), py::none(), py::none());
        return py::make_tuple(image.width, image.height, utf8_text(warning), mapping.field_following,
                              mapping.crack_rings);
      },
      py::arg("texture"), py::arg("name"), py::arg("direction"),
      "_texture_look(texture, name, direction) -> (width, height, warning, field_following, crack_rings): for\n"
      "tailor.tiles, from one decoding: image_size, what tailor map says of a texture that does not wrap\n"
      "('' when it does), naming it `name`, and with `direction` auto_field_following (else None, None).");
}

}  // namespace tailor::python
