#include "harness/run/variant.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

#include "common/format_bytes.hpp"
#include "common/input_error.hpp"
#include "harness/run/backends.hpp"
#include "harness/run/preflight.hpp"

namespace sb {

ProgressFn terminal_progress(const std::string& label) {
  if (!::isatty(STDERR_FILENO)) return {};
  return [label](std::size_t done, std::size_t total) {
    std::fprintf(stderr, "\r[%s] stamp %zu/%zu", label.c_str(), done, total);
    if (done == total) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  };
}

std::function<void(long long, long long, std::size_t)> terminal_settling(const std::string& label) {
  if (!::isatty(STDERR_FILENO)) return {};
  return [label](long long passes, long long max_passes, std::size_t active) {
    if (passes < 0) {
      std::fprintf(stderr, "\r\033[K");  // settling over: clear the line
    } else {
      std::fprintf(stderr, "\r\033[K[%s] settling: pass %lld/%lld, %zu elements active", label.c_str(), passes,
                   max_passes, active);
    }
    std::fflush(stderr);
  };
}

Variant parse_variant(const std::string& text, const std::string& option) {
  Variant v;
  v.label = text;
  std::size_t start = 0;
  const std::size_t colon = text.find(':');
  v.backend = text.substr(0, colon);
  const auto names = backend_names();
  if (std::find(names.begin(), names.end(), v.backend) == names.end())
    throw InputError(option + ": \"" + v.backend + "\" is not a back-end; must be one of " + backend_list(", ") +
                     ", optionally followed by :key=value overrides (e.g. grid:grid.storage=float)");
  if (colon == std::string::npos) return v;
  start = colon + 1;
  while (start <= text.size()) {
    const std::size_t next = text.find(':', start);
    const std::string part = text.substr(start, next == std::string::npos ? std::string::npos : next - start);
    if (part.find('=') == std::string::npos)
      throw InputError(option + ": \"" + part + "\" in \"" + text + "\" must be key=value");
    v.overrides.push_back(part);
    if (next == std::string::npos) break;
    start = next + 1;
  }
  return v;
}

std::string build_notice(const std::string& backend, const Scene& scene) {
  // Measured on flat_stroke.toml (build, sampling and run file of a one-stamp run): 10^6 points
  // 2.7 s and 352 MB, 4 x 10^6 points 10.6 s and 1.16 GB.
  constexpr double kLargeTin = 2e6, kSecondsPerPoint = 2.7e-6, kBytesPerPoint = 290.0;
  const auto n = static_cast<double>(scene.tin.initial_points);
  if (backend != "tin" || n < kLargeTin) return {};
  char text[160];
  std::snprintf(text, sizeof text, "building a TIN of %lld initial points: about %.0f s and %.1f GB",
                static_cast<long long>(scene.tin.initial_points), n * kSecondsPerPoint, n * kBytesPerPoint / 1e9);
  return text;
}

Scene variant_scene(const Variant& v, const Scene& base) {
  if (v.overrides.empty()) return base;
  std::vector<std::string> overrides = base.overrides;
  overrides.insert(overrides.end(), v.overrides.begin(), v.overrides.end());
  return parse_scene(base.text, base.path, overrides, std::filesystem::path(base.path).parent_path());
}

VariantRun run_variant(const Variant& v, const PreparedScene& base, bool show_progress) {
  PreparedScene prepared = base;
  prepared.scene = variant_scene(v, base.scene);
  const Scene& scene = prepared.scene;
  if (v.backend == "tin") {
    prepared.max_added_vertices =
        tin_vertex_allowance(scene, base.schedule.stamps.size(), base.replay, base.memory_limit_bytes);
    prepared.vertex_bound_reason =
        "8 x the vertices of tin.refine_m over the area the stroke disturbs, at most what " +
        (base.memory_limit_bytes ? format_bytes(static_cast<double>(base.memory_limit_bytes)) : std::string("memory")) +
        " holds";
  }
  prepared.rule = ErosionRule::from(scene.material, scene.erosion.settle_tolerance_deg, scene.erosion.rule);

  if (const std::string notice = build_notice(v.backend, prepared.scene); !notice.empty())
    std::fprintf(stderr, "[%s] %s\n", v.label.c_str(), notice.c_str());
  auto terrain = make_terrain(v.backend, prepared.scene, prepared.initial);
  RunCallbacks callbacks;
  callbacks.notice = [label = v.label](const std::string& message) {
    std::fprintf(stderr, "\r[%s] %s\n", label.c_str(), message.c_str());
  };
  if (show_progress) {
    callbacks.progress = terminal_progress(v.label);
    callbacks.settling = terminal_settling(v.label);
  }
  VariantRun out{run_schedule(*terrain, prepared, callbacks), prepared, {}};
  out.run.label = v.label;
  out.run.final_terrain = std::move(terrain);
  out.summary = summarize(out.run, prepared);
  // The run's warnings and the summary's own (reference metrics that could not be computed).
  for (const auto& w : out.summary["warnings"])
    std::fprintf(stderr, "sandbench: warning: [%s] %s\n", v.label.c_str(), w.get<std::string>().c_str());
  return out;
}

std::vector<std::string> scene_overrides(const std::vector<std::string>& unset, const std::vector<std::string>& set) {
  std::vector<std::string> out;
  for (const auto& key : unset) out.push_back(unset_override(key));
  out.insert(out.end(), set.begin(), set.end());
  return out;
}

std::filesystem::path default_run_path(const std::string& scene_path, const std::string& label) {
  std::string safe;
  for (char c : label) safe += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_') ? c : '-';
  return std::filesystem::path(std::filesystem::path(scene_path).stem().string() + "-" + safe + ".h5");
}

}  // namespace sb
