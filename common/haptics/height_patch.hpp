#pragma once
// HeightPatch: everything the servo loop needs from the simulation -- the heights on a small
// square raster around the tool (filled by one Terrain::sample call, never read from the
// terrain itself) and the force parameters of the current tool and material. The simulation
// fills one after each step and publishes it through a PatchBuffer; the servo reads the
// newest without waiting. A 49 x 49 patch is 19 KB; filling it costs one sample() of 2401
// points (grid: O(points); TIN: O(points + sqrt n)).
#include <array>
#include <cstdint>

#include "common/haptics/triple_buffer.hpp"
#include "common/material.hpp"
#include "common/raster.hpp"
#include "common/terrain.hpp"
#include "common/tool.hpp"

namespace sb::haptics {

// The tool and sand as the force model sees them. Fixed size: copying it never allocates.
struct ForceParams {
  static constexpr int kMaxFootprint = 128;     // footprint vertices kept (decimated above)
  double stiffness_n_per_m = 800.0;             // penetration resistance per metre of depth
  double drag_n_s_per_m = 5.0;                  // viscous drag while in sand
  double friction = 0.4;                        // Coulomb coefficient against penetration
  std::array<Vec2, kMaxFootprint> footprint{};  // tool coordinates, CCW
  int footprint_size = 0;
  BottomProfile profile = BottomProfile::Flat;
  double sphere_radius_m = 0.0;
  double heading_rad = 0.0;  // footprint rotation about z
  double reach_m = 0.0;      // largest footprint distance from the origin

  // From the material's haptic parameters and a tool (a pour tool feels like a disk of its
  // pour radius). O(footprint).
  static ForceParams from(const Material& material, const ToolSpec& tool, double heading_rad = 0.0);
};

struct HeightPatch {
  bool valid = false;         // false until the simulation's first publication
  std::uint64_t version = 0;  // increases with every publication
  Vec2 centre_m{0.0, 0.0};    // tool position the patch was centred on
  Raster heights;             // nx = ny = PatchLayout::cells, around centre_m
  ForceParams params;
};

using PatchBuffer = TripleBuffer<HeightPatch>;

// The patch lattice for a tool: `cells` points per side (odd: the centre is a lattice point),
// covering the tool's reach plus a margin the tool may travel before the next publication.
struct PatchLayout {
  std::size_t cells = 49;
  double half_m = 0.04;  // half the side
  double spacing_m = 0.04 / 24;
  static PatchLayout for_tool(double reach_m, double margin_m, std::size_t cells = 49);
};

// Reserves the largest patch in every slot, so publishing never allocates afterwards.
void reserve_patches(PatchBuffer& buffer, std::size_t cells);

// Fills `out` around `centre` from the terrain (one sample() call) and sets its params and
// version. O(cells^2) plus the back-end's sample cost.
void fill_patch(const Terrain& terrain, const Vec2& centre, const PatchLayout& layout, const ForceParams& params,
                std::uint64_t version, HeightPatch& out);

}  // namespace sb::haptics
