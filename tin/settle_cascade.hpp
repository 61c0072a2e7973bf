#pragma once
// Coarse-to-fine settling for the TIN: the cascade of grid/multires_settle.hpp on clusters of
// vertices, so that sand travels long distances where a pass is cheap and a distance is a few
// clusters, and the fine passes (TinTerrain::erode) only finish what is left at the mesh's scale.
// CGAL-free: TinTerrain hands a region of vertices over as plain arrays (settle_with_cascade,
// tin/settle_cascade.cpp) and takes the heights back.
//
// Why. The fine rule moves at most a fraction of a pair's excess per visit: near the critical
// angle it behaves like diffusion, and its tail is long (flat_stroke.toml with a tool deeper
// than the bed: 361k settling visits, the last quarter of the transfers moving a median 7 um),
// at about 1500 instructions a visit on the TIN (CGAL handles, ring cache, re-activation).
//
// The cascade (settle_cascade). Level 0 is the region's vertices (position, barycentric area,
// height, the TIN's edges between them). Level k >= 1 bins the vertices by square cells of side
// 2^(k-1) cell_m (cell_m: the refinement length, tin.refine_m) anchored at the region's lower corner;
// a cluster is the set of level k-1 clusters in one cell (cells nest, so clusters do), with
// area A_I the sum of its children's areas, position their area-weighted centroid and height
// Z_I their area-weighted mean height (the mean of its vertices). Two clusters are adjacent
// when an edge of the TIN joins two of their vertices. Levels are built while a level has at
// least kCascadeMinClusters clusters and merges at least a fifth of its children. Then, from
// the coarsest level to level 1, the level is relaxed with the fine rule (sb::erosion_transfers:
// the same tan_critical, fraction and tan_settle; the edge rule with equal conductances,
// NeighbourLayout::Stencil, as clusters form no fan and have no facet gradient; the edge rule
// never moves more than the gradient rule) over its own active set -- the clusters above
// active vertices and the children of clusters the coarser level changed, joined by the
// neighbours of every cluster that changes -- for at most max_passes_per_level passes, and its
// total change dZ_I (relaxed minus restricted height, so it includes the coarser levels'
// changes) is added to every one of its children. Level 1's change reaches the vertices.
// Then the fine level (CascadeOptions::fine_level): the vertices whose whole ring lies in the
// region are relaxed with the fine rule exactly as TinTerrain::erode applies it (the rule's
// kind, the fan gradient, cotangent conductances over the counter-clockwise ring, the same
// re-activation; drops capped by the steepest facet as the TIN caps them at rest, the fan's
// facets then computed one by one), over plain arrays whose offsets, distances, areas,
// conductances and fan gradient coefficients are laid out once: the diffusive tail at the mesh's scale at about 700
// instructions a visit instead of about 1500. Region vertices have no edge longer than the
// refinement length, so the fine passes would split nothing there. The TIN runs no cascade with
// curvature refinement (tin.curvature_tolerance_m > 0; settle_region.cpp): its crease splits
// need the fine passes, and the clusters cost it accuracy.
//
// Piecewise constant, as the grid: the detail under a cluster (a cut wall, a rim) is kept and
// shifted by the cluster's change; the fine passes settle it locally. A plane's area-weighted
// mean over a cluster is the plane's height at the cluster's centroid, so a plane at repose is
// at repose on every level too: the cascade moves nothing the fine rule would keep.
//
// Conservation (exact): the TIN's volume is sum_v A_v z_v with barycentric areas A_v (the
// integral of a piecewise-linear surface). A coarse transfer of V from I to J changes Z_I by
// -V / A_I and Z_J by V / A_J; adding dZ_I to every child c of I changes the finer volume by
// sum_c A_c dZ_I = A_I dZ_I, the coarse change, because A_I is the sum of its children's areas.
// Conditions: the areas given are the vertices' barycentric areas at the time of the call (the
// mesh does not change during the cascade), every vertex of a cluster gets the same change,
// A_I = sum of children's A. Up to the rounding of the heights (double).
//
// Energy (sum A z^2 / 2, never rising): with Z_I the area-weighted mean of its children, adding
// dZ_I to them changes the finer level's energy by A_I Z_I dZ_I + A_I dZ_I^2 / 2, exactly the
// coarse level's energy change. Each level's relaxation lowers its own energy (each transfer
// moves at most f times the pair's volume excess downhill, f <= 1), and every level is
// restricted from the same fine state before any level changes, so when a level's change is
// added its restricted heights are still the means of its children. By induction the fine
// energy changes by the sum of the levels' relaxations: it never rises. Conditions: the ones
// above, f <= 1 (the scene's default is 0.5), all levels restricted before any is relaxed.
//
// The fine level's transfers are the fine rule's (pairwise, with the same areas): volume exact
// and energy falling by the rule's own argument (erosion_kernel.hpp, "Energy").
//
// Settled state: the cascade only runs before fine passes (TinTerrain::erode), which take the
// vertices it changed, with their neighbours, into L_e: the state returned is at repose under
// the fine rule whenever the fine passes empty L_e, as without the cascade.
//
// Accuracy: as the grid's (grid/multires_settle.hpp, "Accuracy"), a pile spreading over many
// clusters ends flatter, more so with every level: pile.toml on 10^5 initial points, RMSE 11, 91
// and 207 um with 0, 1 and both of its 2 levels (flank 30.03, 29.20, 26.63 degrees). With
// ErosionBudget::cascade false (erosion.cascade) the TIN builds no cluster level and runs only the
// fine level, which is the fine rule itself over arrays.
//
// When (cascade_pays): the runner's settling budgets only (at least kCascadeMinPasses passes,
// at least 8 updates per active vertex), with at least kCascadeMinActive active vertices;
// interactive and stroke steps (4 passes) stay local. (pile.toml settles from about 270
// active vertices: with the cascade, 25 % fewer updates but RMSE 54 -> 64 um, the flank 0.25
// degrees flatter -- sand the clusters moved that the fine rule would have kept -- so small
// active sets settle with the fine passes alone.) The region (settle_with_cascade) is the
// vertices within the active set's bounding box widened by a quarter of its larger side,
// without edges longer than the refinement length (sand leaving the refined zone must go
// through the fine rule, which refines where it flows), and no larger than passes x active
// vertices, so that gathering it costs no more than the passes it may replace.
//
// Cost: O(region x degree) to gather the region (a hash lookup per edge end), O(region) per
// level to restrict and inject, plus the levels' visits (at most max_passes_per_level passes
// each, max_fine_passes on the fine level; counted as updates, the call as one pass); memory
// about 600 B per region vertex (the fine level's laid-out rings), freed on return. What it
// saves: results/cascade.md (the deep stroke's settling updates and time with and without it,
// `erosion.cascade`), measured again by every reproduction.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "common/erosion.hpp"
#include "common/terrain.hpp"

namespace sb::tin {

inline constexpr int kCascadeMinPasses = 32;
inline constexpr std::size_t kCascadeMinActive = 512;
inline constexpr std::size_t kCascadeMinClusters = 16;

// Whether a settling call with this budget and active set runs the cascade first.
inline bool cascade_pays(std::size_t active, const ErosionBudget& budget) {
  return budget.max_passes >= kCascadeMinPasses && active >= kCascadeMinActive && budget.max_updates / 8 >= active;
}

// The region handed to the cascade: per vertex its position (m), barycentric area (m^2),
// height (m; updated in place) and whether it is active; the TIN's edges between region
// vertices as index pairs.
struct CascadeRegion {
  std::vector<double> x, y, area, z;
  std::vector<std::uint8_t> active;
  std::vector<std::uint32_t> edges;  // pairs (a, b), a != b
  // For the fine level (CascadeOptions::fine_level): per vertex whose neighbours are all in
  // the region, its ring counter-clockwise (as TinTerrain::gather_neighbours lists it), in
  // region indices; empty for the others, which the fine level never visits.
  std::vector<std::uint32_t> ring_begin, ring;
  std::size_t size() const { return z.size(); }
};

struct CascadeLevelReport {
  std::size_t clusters = 0;
  int passes = 0;
  std::size_t updates = 0;
  std::size_t changed = 0;                         // clusters whose height changed
  double energy_before = 0.0, energy_after = 0.0;  // sum A Z^2 / 2, when measured
};
struct CascadeReport {
  std::vector<CascadeLevelReport> levels;  // index 0: level 1
  CascadeLevelReport fine;                 // the fine level (fine_level)
  std::size_t updates = 0;                 // cluster and vertex visits, all levels
  std::size_t transfers = 0;
  double moved_m3 = 0.0;
};

struct CascadeOptions {
  double cell_m = 0.0;  // level 1's cell side (> 0)
  int max_passes_per_level = 512;
  // A node leaves its level's active set after this many idle visits. One suffices: every
  // change that can make a node unstable re-activates it (a giver its whole ring, a receiver
  // itself, and under the gradient rule its ring, whose fan gradients read it), and the TIN's
  // passes check every vertex the cascade changed anyway, so a second idle visit only adds
  // updates (compare the shipped scenes' settling updates with 2 to see it).
  int idle_passes = 1;
  int max_levels = 10;
  bool measure_energy = false;
  // After level 1, relax the vertices themselves with the fine rule as given (its kind, Fan
  // conductances over the rings): the fine passes' visits without the TIN's bookkeeping.
  bool fine_level = false;
  int max_fine_passes = 512;
};

// The cascade (above) on `region`: its heights are changed in place (piecewise constant per
// level-1 cluster). The rule is the fine one (its kind is ignored: the edge rule is used).
CascadeReport settle_cascade(CascadeRegion& region, const ErosionRule& rule, const CascadeOptions& options);

}  // namespace sb::tin
