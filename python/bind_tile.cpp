// tailor.tile: make_tileable on a numpy image or an image file, as `tailor tile` (report=True adds
// the JSON of `tailor tile --json`); tailor.tile_set: the maps of a material with one cut, as
// `tailor tile --set`.
#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "bindings.h"
#include "tailor/image.h"
#include "tailor/material.h"
#include "tailor/report.h"
#include "tailor/tiling.h"

namespace tailor::python {
namespace {

// Whether two paths name one file: the same device and inode when both exist, else the same
// normalised absolute path (as the command's output checks compare them).
bool same_file(const std::string& a, const std::string& b) {
  std::error_code ea, eb;
  if (std::filesystem::exists(a, ea) && std::filesystem::exists(b, eb)) return std::filesystem::equivalent(a, b, ea);
  return std::filesystem::absolute(a, ea).lexically_normal() == std::filesystem::absolute(b, eb).lexically_normal();
}

// (H, W) or (H, W, C) uint8 with C in 1..4 -> Image (rows top first, interleaved channels).
Image image_from_array(const py::array& array) {
  if (!array.dtype().equal(py::dtype::of<uint8_t>()))
    raise_error("image must be a uint8 array (H, W) or (H, W, C), got " + describe(array));
  if (array.ndim() != 2 && array.ndim() != 3)
    raise_error("image must be a uint8 array (H, W) or (H, W, C), got " + describe(array));
  Image image;
  image.height = static_cast<int>(std::min<py::ssize_t>(array.shape(0), kMaxImageSide + 1));
  image.width = static_cast<int>(std::min<py::ssize_t>(array.shape(1), kMaxImageSide + 1));
  image.channels = array.ndim() == 3 ? static_cast<int>(std::min<py::ssize_t>(array.shape(2), 5)) : 1;
  // The size is checked before the pixels are copied.
  if (image.width > kMaxImageSide || image.height > kMaxImageSide || image.channels > 4 || image.width < 1 ||
      image.height < 1)
    raise_status(Status::error(ErrorCode::kInvalidImage, "image", "unsupported image size " + describe(array)));
  const auto typed = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>::ensure(array);
  image.pixels.resize(static_cast<size_t>(typed.size()));
  std::memcpy(image.pixels.data(), typed.data(), image.pixels.size());
  return image;
}

// The options tile() and tile_set() share, as `tailor tile` takes them.
TileOptions tile_options(int block, int overlap, uint64_t seed, int symmetry, bool same_size) {
  TileOptions options;
  options.block = block;
  options.overlap = overlap;
  options.seed = seed;
  options.symmetry = symmetry;
  options.same_size = same_size;
  return options;
}

py::array array_from_image(Image&& image) {
  auto* owned = new Image(std::move(image));
  py::capsule owner(owned, [](void* p) { delete static_cast<Image*>(p); });
  std::vector<py::ssize_t> shape = {owned->height, owned->width, owned->channels};
  return py::array_t<uint8_t>(shape, owned->pixels.data(), owner);
}

}  // namespace

void bind_tile(py::module_& m) {
  const TileOptions d;
  m.def(
      "tile",
      [](const py::object& image_or_path, int block, int overlap, uint64_t seed, bool fit_period, int symmetry,
         bool same_size, bool report, const py::object& progress) -> py::object {
        Image exemplar;
        TileRun run;
        if (py::isinstance<py::array>(image_or_path)) {
          exemplar = image_from_array(image_or_path.cast<py::array>());
        } else {
          run.input = path_of(image_or_path);
          Status s;
          {
            const py::gil_scoped_release release;
            s = load_image(run.input, exemplar);
          }
          if (!s) raise_status(s);
        }
        TileOptions options = tile_options(block, overlap, seed, symmetry, same_size);
        options.fit_period = fit_period;
        ProgressBridge bridge(progress);
        options.progress = bridge.function();
        run.input_width = exemplar.width;
        run.input_height = exemplar.height;
        run.input_channels = exemplar.channels;
        run.options = options;
        std::vector<Image> tiles;
        Status status;
        {
          const py::gil_scoped_release release;
          const auto start = std::chrono::steady_clock::now();
          status = make_tile_variants(exemplar, options, 1, tiles, &run.report);
          run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          if (status && report) {  // the metrics against the input as given, as `tailor tile --json`
            run.tiles.resize(1);
            status = tile_metrics(tiles[0], &exemplar, run.tiles[0].metrics);
            run.tiles[0].targets_met = meets_tile_targets(run.tiles[0].metrics, &run.tiles[0].targets_failed);
            run.worst.metrics = worst_tile_metrics(run.tiles);
            run.worst.targets_met = meets_tile_targets(run.worst.metrics, &run.worst.targets_failed);
          }
        }
        bridge.finish(status.with_file(run.input.empty() ? "image" : run.input));
        py::array tile = array_from_image(std::move(tiles[0]));
        if (!report) return tile;
        return py::make_tuple(tile, json_to_dict(tile_report_json(run)));
      },
      py::arg("image"), py::arg("block") = d.block, py::arg("overlap") = d.overlap, py::arg("seed") = d.seed,
      py::arg("fit_period") = d.fit_period, py::arg("symmetry") = d.symmetry, py::arg("same_size") = d.same_size,
      py::arg("report") = false, py::arg("progress") = py::none(),
      R"(tile(image, block=32, overlap=0, seed=1, fit_period=False, symmetry=1, same_size=False, report=False,
     progress=None)

Makes a texture self-tileable (quadrant swap + image quilting), as `tailor tile`. image: a uint8
array (H, W) or (H, W, C) with C in 1..4, or an image file path. Returns the tile as a uint8 array
(H', W', C); with report=True, (tile, dict) where the dict is `tailor tile --json`'s report
(metrics against the input). symmetry=4 gives a tile twice the input's (square) side, or its side
with same_size=True. The same seed gives the same tile. The GIL is released while it
works; progress works as in map().)");
}

void bind_tile_set(py::module_& m) {
  const TileOptions d;
  m.def(
      "tile_set",
      [](const std::vector<py::object>& map_paths, const py::object& output, const std::vector<py::object>& normal_maps,
         int block, int overlap, uint64_t seed, int symmetry, bool same_size, const py::object& progress) -> py::list {
        std::vector<std::string> paths, normals, written;
        for (const py::object& p : map_paths) paths.push_back(path_of(p));
        for (const py::object& p : normal_maps) normals.push_back(path_of(p));
        const std::string folder = path_of(output);
        if (paths.empty()) raise_error("tile_set needs at least one map");
        for (const std::string& n : normals)
          if (std::find(paths.begin(), paths.end(), n) == paths.end())
            raise_status(Status::error(ErrorCode::kInvalidArgument, n, "normal_maps must name maps of the set"));
        // Each output is named as `tailor tile --set` names it, inside `output`.
        for (const std::string& in : paths) {
          const std::string out = folder + "/" + tile_set_file_name(in);
          if (std::find(written.begin(), written.end(), out) != written.end())
            raise_status(Status::error(ErrorCode::kInvalidArgument, in,
                                       "two maps of the set would be written to the same file name", out));
          written.push_back(out);
        }
        std::error_code ec;
        if (std::filesystem::exists(folder, ec) && !std::filesystem::is_directory(folder, ec))
          raise_status(Status::error(ErrorCode::kInvalidArgument, folder, "the output is not a folder"));
        // The outputs must not replace the maps they are made from (the command refuses that too).
        std::vector<std::string> outputs = written;
        outputs.push_back(folder + "/material.json");
        for (const std::string& out : outputs)
          for (const std::string& in : paths)
            if (same_file(in, out))
              raise_status(Status::error(ErrorCode::kInvalidArgument, out, "the output would overwrite an input"));
        std::vector<TileMap> maps(paths.size());
        TileOptions options = tile_options(block, overlap, seed, symmetry, same_size);
        ProgressBridge bridge(progress);
        options.progress = bridge.function();
        Status status;
        std::vector<std::vector<Image16>> tiles;
        {
          const py::gil_scoped_release release;
          for (size_t i = 0; i < paths.size() && status; ++i) {
            status = load_image16(paths[i], maps[i].image).with_file(paths[i]);
            maps[i].normal = std::find(normals.begin(), normals.end(), paths[i]) != normals.end();
            bool dx_name = false;  // a *_normal_dx map turns the other way round with symmetry 4
            material_role_from_name(paths[i], &dx_name);
            maps[i].directx = maps[i].normal && dx_name;
            if (status && (maps[i].image.width != maps[0].image.width || maps[i].image.height != maps[0].image.height))
              status = Status::error(ErrorCode::kInvalidImage, paths[i], "every map of a set must have the same size",
                                     std::to_string(maps[i].image.width) + "x" + std::to_string(maps[i].image.height) +
                                         ", but " + paths[0] + " is " + std::to_string(maps[0].image.width) + "x" +
                                         std::to_string(maps[0].image.height));
          }
          if (status) status = make_tileable_set(maps, options, 1, tiles).with_file(paths[0]);
          std::error_code created;
          if (status && !std::filesystem::is_directory(folder, created) &&
              !std::filesystem::create_directories(folder, created))
            status = Status::error(ErrorCode::kIo, folder, "cannot create the output folder");
          for (size_t i = 0; i < written.size() && status; ++i) status = write_png16(written[i], tiles[0][i]);
          if (status) {  // material.json, as the command writes it (tailor.map(material=folder) reads it)
            TileSetRecord record;
            record.symmetry = options.symmetry;
            record.width = tiles[0][0].width;
            record.height = tiles[0][0].height;
            for (size_t i = 0; i < paths.size(); ++i)
              record.maps.push_back({tile_set_file_name(paths[i]),
                                     paths[i],
                                     maps[i].normal,
                                     maps[i].image.bits,
                                     maps[i].image.channels,
                                     {},
                                     maps[i].directx});
            status = write_tile_set_record(folder, record);
          }
        }
        bridge.finish(status);
        py::list paths_written;
        for (const std::string& path : written) paths_written.append(path_text(path));
        return paths_written;
      },
      py::arg("maps"), py::arg("output"), py::arg("normal_maps") = std::vector<py::object>{},
      py::arg("block") = d.block, py::arg("overlap") = d.overlap, py::arg("seed") = d.seed,
      py::arg("symmetry") = d.symmetry, py::arg("same_size") = d.same_size, py::arg("progress") = py::none(),
      R"(tile_set(maps, output, normal_maps=(), block=32, overlap=0, seed=1, symmetry=1, same_size=False, progress=None) -> list

Makes the maps of one material (colour, normal, roughness, height... image files of one size)
self-tileable with one cut for all, as `tailor tile --set MAPS --normal-map N -o OUTPUT/`: each is
written into the folder `output` (created if missing) under its own name as .png, 8 or 16 bits as
its input, with the command's material.json beside them; returns the written maps' paths in the
order of `maps`. normal_maps: the maps (the same paths) that are normal maps, blended as vectors.
symmetry=4 (`--symmetry 4`): one quarter-turn tile for all, normal maps turned with their content,
recorded in material.json so that map(material=output/material.json) maps with symmetry 4;
same_size as in tile().)");
}

}  // namespace tailor::python
