// Self-tileable textures: time of make_tileable for 128, 512 and 1024 px exemplars (grey and
// RGB; grey also with symmetry 4), of the variants and of the quality metrics. Target: < 1 s for 512 x 512 RGB on one
// core. Each benchmark reports the process's peak resident memory so far (getrusage ru_maxrss) as the counter
// peak_rss_mb. Exemplars come from the shared data folder (TAILOR_SHARED_DATA); the 512 and 1024 px RGB ones are the
// 300 px water photo resampled (bicubic) to that size.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <map>
#include <string>

#include "tailor/image.h"
#include "tailor/image_ops.h"
#include "tailor/tiling.h"

namespace {

using tailor::Image;

const std::string kTextures = std::string(TAILOR_SHARED_DATA) + "/textures/";

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux: kilobytes
}

//! name -> image, loaded (and resampled) once.
const Image& exemplar(const std::string& name, int size) {
  static std::map<std::string, Image> cache;
  const std::string key = name + "@" + std::to_string(size);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  Image im;
  if (!tailor::load_image(kTextures + name, im).is_ok()) return cache[key];
  if (im.width != size || im.height != size) {
    Image resized;
    if (tailor::resize_image(im, size, size, resized).is_ok()) im = std::move(resized);
  }
  return cache[key] = std::move(im);
}

void run_tile(benchmark::State& state, const std::string& name, int symmetry = 1) {
  const int size = static_cast<int>(state.range(0));
  const Image& ex = exemplar(name, size);
  if (ex.empty()) {
    state.SkipWithError(("cannot load " + kTextures + name).c_str());
    return;
  }
  tailor::TileOptions options;
  options.symmetry = symmetry;
  for (auto _ : state) {
    Image tile;
    const tailor::Status s = tailor::make_tileable(ex, options, tile);
    if (!s.is_ok()) state.SkipWithError(s.message().c_str());
    benchmark::DoNotOptimize(tile.pixels.data());
  }
  state.counters["megapixels_per_s"] =
      benchmark::Counter(static_cast<double>(size) * size * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["peak_rss_mb"] = peak_rss_mb();
}

void BM_TileRgb(benchmark::State& state) { run_tile(state, "water-caustics-300.jpg"); }
void BM_TileGrey(benchmark::State& state) { run_tile(state, "gravel-gray-512.png"); }
// --symmetry 4: a tile twice the side (up to a 1024 px exemplar), blocks from four turns up to 512 px.
void BM_TileQuarterTurnGrey(benchmark::State& state) { run_tile(state, "gravel-gray-512.png", 4); }

void BM_TileVariants4Rgb512(benchmark::State& state) {
  const Image& ex = exemplar("water-caustics-300.jpg", 512);
  for (auto _ : state) {
    std::vector<Image> tiles;
    const tailor::Status s = tailor::make_tile_variants(ex, tailor::TileOptions{}, 4, tiles);
    if (!s.is_ok()) state.SkipWithError(s.message().c_str());
    benchmark::DoNotOptimize(tiles.data());
  }
  state.counters["peak_rss_mb"] = peak_rss_mb();
}

void BM_TileMetricsRgb512(benchmark::State& state) {
  const Image& ex = exemplar("water-caustics-300.jpg", 512);
  Image tile;
  if (!tailor::make_tileable(ex, tailor::TileOptions{}, tile).is_ok()) {
    state.SkipWithError("tiling failed");
    return;
  }
  for (auto _ : state) {
    tailor::TileMetrics m;
    const tailor::Status s = tailor::tile_metrics(tile, &ex, m);
    if (!s.is_ok()) state.SkipWithError(s.message().c_str());
    benchmark::DoNotOptimize(m.patch_coherence);
  }
  state.counters["peak_rss_mb"] = peak_rss_mb();
}

void BM_EstimatePeriod512(benchmark::State& state) {
  const Image& ex = exemplar("brick-gray-512.png", 512);
  for (auto _ : state) {
    const tailor::PeriodEstimate p = tailor::estimate_period(ex);
    benchmark::DoNotOptimize(p.period_x);
  }
}

}  // namespace

BENCHMARK(BM_TileRgb)->Arg(128)->Arg(512)->Arg(1024)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TileGrey)->Arg(128)->Arg(512)->Arg(1024)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TileQuarterTurnGrey)->Arg(128)->Arg(512)->Arg(1024)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_TileVariants4Rgb512)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_TileMetricsRgb512)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EstimatePeriod512)->Unit(benchmark::kMillisecond);
