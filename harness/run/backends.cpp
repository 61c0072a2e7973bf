#include "harness/run/backends.hpp"

#include "common/input_error.hpp"
#include "grid/grid_terrain.hpp"
#include "grid/sparse_terrain.hpp"
#include "tin/tin_terrain.hpp"

namespace sb {

namespace {
constexpr Backend kBackends[] = {
    {"tin", tin::make_tin_terrain},
    {"grid", grid::make_grid_terrain},
    {"sparse", grid::make_sparse_terrain},
};
}  // namespace

std::span<const Backend> backends() { return kBackends; }

std::vector<std::string> backend_names() {
  std::vector<std::string> names;
  for (const Backend& b : kBackends) names.emplace_back(b.name);
  return names;
}

std::string backend_list(std::string_view separator) {
  std::string text;
  for (const Backend& b : kBackends) text += (text.empty() ? "" : std::string(separator)) + std::string(b.name);
  return text;
}

std::unique_ptr<Terrain> make_terrain(const std::string& backend, const Scene& scene, const HeightField& initial) {
  for (const Backend& b : kBackends)
    if (b.name == backend) return b.make(scene, initial);
  throw InputError("--backend " + backend + " is not a back-end; must be one of " + backend_list());
}

}  // namespace sb
