#pragma once
// The resource pre-flight: before a model is allocated, the elements and bytes a run will
// need, from the scene alone (grid nodes, sparse blocks, TIN vertices from its refinement
// length over the area the stroke disturbs, heightmap pixels, rasters, step records), so
// that a run too large for the memory it may use is refused up front (InputError, exit 2,
// naming the scene keys that size it) and a large one says so before it starts. The TIN
// estimate also bounds the run: a TIN that grows past it stops with a message
// (PreparedScene::max_added_vertices). Estimates are upper bounds of the model's own
// bookkeeping (the back-ends' stated bytes per element), not of the allocator's overhead.
// Everything here is O(1) per run apart from reading a heightmap's PNG header.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/scene.hpp"

namespace sb {

// One part of a run's memory: what it is, the scene keys that size it, how many elements.
struct ResourceItem {
  std::string what;  // e.g. "dense grid nodes"
  std::string keys;  // e.g. "grid.cell_m, domain.size_m"
  double elements = 0.0;
  double bytes = 0.0;
};

struct ResourceEstimate {
  std::vector<ResourceItem> items;
  double bytes() const;
  // The largest item, named in refusals and out-of-memory messages; nullptr when empty.
  const ResourceItem* largest() const;
};

// A back-end run of the scene (a variant's own scene, with its overrides applied).
struct PlannedRun {
  std::string backend;  // "tin", "grid", "sparse"
  Scene scene;
};

// The memory of running `runs` one after another in one process whose results are all kept
// (as `compare` does), with `stamps` stamps each, plus what they share (initial surface,
// rasters); `replay`: the stamps are a session's, not the scene's stroke. Throws InputError
// for an unreadable heightmap (as loading it would).
ResourceEstimate estimate_resources(const std::vector<PlannedRun>& runs, std::size_t stamps, bool replay);

// How many vertices a TIN run of the scene may add to its initial model before it is stopped:
// a generous multiple of the estimate (refinement at its finest length over the disturbed
// area, and the stamps' contours), and never more than `memory_limit_bytes` holds (0: no limit).
std::size_t tin_vertex_allowance(const Scene& scene, std::size_t stamps, bool replay, std::uint64_t memory_limit_bytes);

// Bytes the process may still allocate: /proc/meminfo's MemAvailable, less when the cgroup's
// memory.max leaves less; nullopt when neither can be read.
std::optional<std::uint64_t> available_memory_bytes();

// "--max-memory" values: bytes, or a number with a suffix K, M, G, T (powers of 1024), e.g.
// "512M", "1.5G". nullopt when the text is not one (or is not > 0).
std::optional<std::uint64_t> parse_memory_size(const std::string& text);

// Refuses (InputError naming the keys of the largest items and the limit) when the estimate
// exceeds `max_memory` (when given) or else the available memory; prints a warning on stderr
// when it exceeds kLargeRunBytes or half the limit. Remembers the largest item for
// out_of_memory_context(). Call once, before the model is allocated.
// Returns the limit it applied (0 when none was known).
std::uint64_t preflight(const ResourceEstimate& estimate, std::optional<std::uint64_t> max_memory);
inline constexpr double kLargeRunBytes = 2.0 * (1u << 30);

// What the last pre-flight found largest ("grid.cell_m: dense grid nodes, 9e8 elements,
// about 9 GB"), for an out-of-memory message; empty when no pre-flight ran.
std::string out_of_memory_context();
// Sets it (a reader about to allocate what an input declares, e.g. "run file X: /final/raster").
void set_out_of_memory_context(std::string what);

}  // namespace sb
