#include "harness/run/backends.hpp"

#include "common/input_error.hpp"
#include "grid/grid_terrain.hpp"
#include "grid/sparse_terrain.hpp"
#include "tin/tin_terrain.hpp"

namespace sb {

std::vector<std::string> backend_names() { return {"tin", "grid", "sparse"}; }

std::unique_ptr<Terrain> make_terrain(const std::string& backend, const Scene& scene, const HeightField& initial) {
  if (backend == "tin") return tin::make_tin_terrain(scene, initial);
  if (backend == "grid") return grid::make_grid_terrain(scene, initial);
  if (backend == "sparse") return grid::make_sparse_terrain(scene, initial);
  throw InputError("--backend " + backend + " is not a back-end; must be one of tin | grid | sparse");
}

}  // namespace sb
