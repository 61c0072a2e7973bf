// Offscreen rendering on llvmpipe (OSMesa): one whole picture -- mesh preparation, drawing
// at 2x supersampling, read-back and downsampling -- of a sand surface with about 10^5 and
// 10^6 triangles at the default 1024 x 768, plain and with the wireframe overlay. Wall
// time (rasterisation runs on llvmpipe's own threads).
//
//   build/<dir>/tests/render_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>

#include "harness/render/frame.hpp"
#include "harness/render/mesh.hpp"
#include "harness/render/renderer.hpp"

namespace {

// A dune field with a trench on an n x n lattice over 0.7 m: 2 (n - 1)^2 triangles.
sb::Raster surface(std::size_t triangles) {
  const auto n = static_cast<std::size_t>(std::lround(std::sqrt(triangles / 2.0))) + 1;
  const double size = 0.7071;
  sb::Raster r = sb::Raster::covering({{0.0, 0.0}, {size, size}}, size / static_cast<double>(n - 1));
  for (std::size_t iy = 0; iy < r.ny; ++iy)
    for (std::size_t ix = 0; ix < r.nx; ++ix) {
      const sb::Vec2 p = r.point(ix, iy);
      const double trench = std::abs(p.x() - p.y()) < 0.03 && p.x() > 0.3 && p.x() < 0.4 ? 0.01 : 0.0;
      r.at(ix, iy) = 0.1 + 0.01 * std::sin(25 * p.x() + 3 * std::sin(9 * p.y())) - trench;
    }
  return r;
}

void render(benchmark::State& state, bool wireframe) {
  const sb::Raster raster = surface(static_cast<std::size_t>(state.range(0)));
  const sb::SurfaceMesh mesh = sb::mesh_from_raster(raster);
  const sb::RenderFrame frame = sb::make_frame({{nullptr, &raster}}, sb::FrameRegion::Domain);
  sb::Renderer renderer;
  sb::RenderOptions options;  // the defaults: oblique, 1024 x 768, 2x supersampling
  options.wireframe = wireframe;
  for (auto _ : state) {
    sb::Image image = renderer.render(mesh, frame, options);
    benchmark::DoNotOptimize(image.bytes().data());
  }
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
  state.counters["triangles/s"] =
      benchmark::Counter(static_cast<double>(mesh.triangles.size()), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_Render(benchmark::State& state) { render(state, false); }
void BM_RenderWireframe(benchmark::State& state) { render(state, true); }

// Mesh preparation alone (normals, skirts; edges for the wireframe): the CPU share.
void BM_PrepareMesh(benchmark::State& state) {
  const sb::Raster raster = surface(static_cast<std::size_t>(state.range(0)));
  const sb::SurfaceMesh mesh = sb::mesh_from_raster(raster);
  for (auto _ : state) {
    sb::RenderMesh m = sb::prepare_render_mesh(mesh, sb::Vec3(0.35, 0.35, 0.1), state.range(1) != 0);
    benchmark::DoNotOptimize(m.positions.data());
  }
}

BENCHMARK(BM_Render)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RenderWireframe)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_PrepareMesh)->Args({100000, 0})->Args({1000000, 0})->Args({1000000, 1})->Unit(benchmark::kMillisecond);

}  // namespace
