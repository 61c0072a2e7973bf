#!/usr/bin/python3
"""The reproduction driver, run by `make reproduce`: every experiment at the paper's scale,
figures and tables into results/, and results/REPORT.md that compares each claim of the
paper with what we measured. Run files go to results/runs/ (not committed).

Each experiment declares its runs; the driver collects every run not yet done (by this
binary, with these inputs) from all experiments, hands them to one engine -- `local` (a pool
of --jobs on this machine) or `slurm` (one job array; see engines.py) -- and then lets the
experiments aggregate. Finished runs are reused, so an interrupted reproduction resumes and
a second one runs nothing."""
import argparse
import os
import platform
import resource
import subprocess
import time
from pathlib import Path

import engines
import sbrun
import exp_accuracy
import exp_alpha_flat
import exp_bars
import exp_cascade
import exp_cliffs
import exp_drift
import exp_fig5_6
import exp_fig7
import exp_fig8_9
import exp_haptics
import exp_memory
import exp_orientation
import exp_pile_positions
import exp_pile_relax
import exp_settling
import exp_sparse
import exp_stability

EXPERIMENTS = {
    "fig5_6": exp_fig5_6,
    "fig7": exp_fig7,
    "fig8_9": exp_fig8_9,
    "memory": exp_memory,
    "sparse": exp_sparse,
    "drift": exp_drift,
    "alpha_flat": exp_alpha_flat,
    "accuracy": exp_accuracy,
    "orientation": exp_orientation,
    "pile_relax": exp_pile_relax,
    "pile_positions": exp_pile_positions,
    "settling": exp_settling,
    "cascade": exp_cascade,
    "stability": exp_stability,
    "cliffs": exp_cliffs,
    "bars": exp_bars,
    "haptics": exp_haptics,
}


def package_version(name):
    proc = subprocess.run(["dpkg-query", "-W", "-f=${Version}", name], capture_output=True, text=True)
    return proc.stdout.strip() or "?"


def machine_header(ctx):
    """The binary, the runs behind the numbers and the machine. Stable when nothing reran (no
    date of today, no commit of HEAD), so a second reproduction leaves REPORT.md as it was."""
    cpu, flags = "unknown", set()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name") and cpu == "unknown":
                cpu = line.split(":", 1)[1].strip()
            elif line.startswith("flags") and not flags:
                flags = set(line.split(":", 1)[1].split())
    except OSError:
        pass
    # The grid kernel's lanes follow the CPU (grid/erosion_kernel.hpp, has_avx512 / has_avx2), and
    # with them the grid's times: eight nodes at once with AVX-512, four with AVX2.
    lanes = ("AVX-512" if {"avx512f", "avx512vl", "avx512dq", "avx512bw"} <= flags
             else "AVX2" if "avx2" in flags else "SSE2")
    compiler = subprocess.run(["c++", "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    libs = ", ".join(f"{n} {package_version(p)}" for n, p in
                     [("CGAL", "libcgal-dev"), ("Eigen", "libeigen3-dev"), ("HDF5", "libhdf5-dev"),
                      ("OSMesa", "libosmesa6-dev"), ("OpenVDB", "libopenvdb-dev")])
    sides = list(ctx.used.values())
    builds = sorted({s["binary"]["build_id"] for s in sides})
    commits = sorted({s["binary"]["commit"] for s in sides})
    dates = sorted(s["finished"] for s in sides)
    runs = (f"- runs: {len(sides)} sandbench runs, all by build {', '.join(builds)} (commit {', '.join(commits)}), "
            f"finished {dates[0]}..{dates[-1]}\n" if sides else "")
    return (f"- profile: {ctx.profile_name}\n"
            f"- binary: {ctx.binary['version']}; compiler {compiler}\n" + runs +
            f"- machine: {platform.machine()}, {cpu}, {len(os.sched_getaffinity(0))} cores, the grid kernel in {lanes} "
            f"lanes; {platform.platform()}\n"
            f"- libraries: {libs}\n")


def run_experiments(ctx, names):
    """Each experiment's report section. Experiments raise MissingRuns until their runs are
    done; all missing runs of a round go to the engine together (one job array on SLURM)."""
    sections = {}
    for round_ in range(1, 10):
        missing = {}
        for i, name in enumerate(names, 1):
            if name in sections:
                continue
            start = time.monotonic()
            try:
                sections[name] = EXPERIMENTS[name].run(ctx)
                sbrun.progress(f"[{i}/{len(names)}] {name} done in {time.monotonic() - start:.0f} s")
            except sbrun.MissingRuns as m:
                for spec in m.specs:
                    missing.setdefault(spec["name"], spec)
                sbrun.progress(f"[{i}/{len(names)}] {name}: {len(m.specs)} runs to do")
        if not missing:
            return [sections[n] for n in names]
        sbrun.progress(f"round {round_}: {len(missing)} runs to do on the {ctx.engine.name} engine")
        ctx.engine.execute(list(missing.values()), "runs")
    raise RuntimeError("experiments still declare new runs after 9 rounds")


INTRO = """The paper's setup: a square terrain whose diagonal is 1 m, a disk tool (radius 2 cm, 32-gon,
1 cm deep) pulled along the diagonal, alpha_flat 0.4 degrees, critical angle 30 degrees. Both back-ends
receive the same stamp schedule (`experiments/scenes/flat_stroke.toml` with `--set` overrides), and the
figures keep the paper's erosion rule (`erosion.rule = "edge"`). The TIN stamps the tool with the corners its
mesh resolves (about one per `tin.refine_m` of perimeter: 16 of the 32 at the default refinement, same area),
the grid rasterises the 32-gon. Times are
wall seconds summed over the whole stroke, as in the paper; this machine is shared, so compare ratios and
exponents rather than absolute times. The paper's machine was a Core 2 Duo at 1.8 GHz (2008).

TIN size N: the paper's TIN had N vertices before the stroke; ours gets them with `tin.initial_points = N`
(a jittered lattice on the flat surface). Left to itself our TIN starts from the 4 corners of a flat domain;
the grid is given the same number of nodes.
"""


# Where a back-end loses, whether the method or our implementation loses. The judgement comes from
# profiles and experiments made while developing, cited here; the tables below are this run's numbers.
METHOD_OR_CODE = """## Where a back-end loses: the method or our code?

A comparison is only worth what its weakest contender is. These judgements come from profiles and
interleaved runs made during development (medians on a shared 2-core machine; see the project's closing
notes); the tables below are this run's.

- **Which machine**: the ratios move with the CPU, because the grid's kernel runs its visits in the widest
  lanes the CPU has (the header above names them) and the TIN's visits are scalar. The judgements below
  were measured where the grid runs in AVX-512 lanes (an EPYC of the Zen 4 kind), unless they say
  otherwise; on an EPYC without AVX-512 (AVX2 lanes, four at a time) the grid's steps take 2-2.8x as
  long on the pile and 1.7-2.4x on the trench, the TIN's 1.2-2x (medians of different sessions on the
  two machines, so rough), so every TIN / grid time ratio is smaller there; the bars table below measures the pile's and the trench's bars on this run's machine.
  Until this round the gradient rule, the scenes' default, ran in AVX2 lanes not at all
  but one node at a time: **our code** (the grid below its own limit on such CPUs), fixed: four at a
  time, bit for bit the scalar visits (`grid_bench`: pile 14 -> 26 M updates/s, stroke 19 -> 44; the
  grid's step on `pile.toml` 0.186 -> 0.141 ms, `trench.toml` 0.310 -> 0.170, `flat_stroke.toml`
  0.072 -> 0.058; medians of 9 interleaved runs).
- **TIN step time on the trench**: was **our code** several times over, now mostly the method. Each stamp
  re-activated its whole re-triangulated region, convex tools kept corners the mesh cannot resolve, contour
  pieces were subdivided far below the refinement length, every erosion visit walked the triangulation for
  its neighbours, the walls of passed stamps left vertex pairs under a millimetre apart (tiny areas that
  throttle every transfer through them; now thinned once the stamp has passed), and a split measured its
  volume change over a box of its surroundings (now over the faces the insertion replaced). The TIN's
  trench step fell from 1.24 ms three rounds ago to 0.79 ms; the grid's, brought to its own limit, from
  0.24 to 0.10 ms, so the ratio is 7.8-8.1x (interleaved medians, 7 rounds, at the start and the end of
  the last round, whose grid kernel got faster and whose TIN work went to settling and to the cliffs). Where the grid runs in
  AVX2 lanes, 4.8-5.6x (interleaved medians of 7 and 9 rounds, with the gradient rule in those lanes),
  above the bar of 5x by about a tenth there, by 60 % with AVX-512. Two more causes in **our code**,
  fixed this round: step 1e removed every vertex left at the tool's level, so the sand sliding in from
  the walls split the floor's edges again (23 removals and 42 splits a step); it now keeps one wherever
  none lies within half `tin.refine_m`. And CGAL's removal of a vertex fills the hole through lists
  allocated edge by edge; an interior vertex is now removed by flips (to degree 3, then Lawson flips:
  the same Delaunay mesh), 7.5k -> 4.2k instructions a removal. Together 14 % fewer instructions in the
  strokes of `trench.toml`, `trench_azimuth.toml` at 4 azimuths and `flat_stroke.toml` (callgrind; the
  pile's pours, which remove almost nothing, the same work), the TIN's trench step 1.06 -> 0.94 ms
  (interleaved medians of 9 on the AVX2 machine, the grid's 0.24-0.26 ms there): 3.7x where the grid runs in AVX2
  lanes (4.0x in the reproduction that wrote this text; the bars table has this run's), about 7x with
  AVX-512 (estimated from the previous 7.8-8.1x, not measured). Where it goes: the TIN needs
  fewer erosion updates than the grid during the stroke (0.43x on the trench, 0.62x on the pile: the
  method's advantage, fewer elements), but one update costs 6-14x the grid's (about 100 ns on a settled
  mesh, 130-240 ns during a stroke with its splits, against 14-28 ns for the grid's eight-lane visits), and
  a stamp 10-24x (re-triangulating around every pose). A TIN visit reads a ring of scattered vertex records
  in CGAL's pointer-linked triangulation, computes cotangent weights and a fan gradient, and is about 1,500
  instructions; the grid's is about 150, vectorised. Of a visit on the pile (callgrind, 1,360
  instructions): reading the ring's heights, areas and offsets from scattered vertex records about 260, the
  rule with its fan gradient and cotangent weights about 500, re-activation and the lists about 430 (the
  gradient rule re-activates each receiver's ring too), refinement checks and splits about 160.
  Re-activating only the giver's ring, as the grid re-activates only the giver's 3 x 3 block, was tried:
  steps 3-12 % faster, but the poured pile 47.6 -> 58.8 um and the trench's worst wall over 0-90 degrees
  0.45 -> 0.90 degrees from critical (medians of 5 interleaved runs): a receiver's neighbours read its
  height in their fan gradients, so those visits are needed; not kept (tried again this round, during
  strokes only: 6 % fewer instructions in the strokes, the pile at its pour point 40.6 -> 47.7 um, 39.4
  against 38.6 over eight pour points). Laying out each cached
  ring's cotangent weights and fan-gradient coefficients once per star (as the cascade's fine level does)
  was tried: 1,206 instructions a visit on the pile (its step 0.202 -> 0.185 ms, 9 interleaved rounds),
  but no gain on the trench or `flat_stroke.toml` (stamps re-walk the stars about every ten visits: 0.78 ->
  0.79 and 0.70 -> 0.71 ms), for the pile's peak memory 119 -> 195 kB (the grid's: 163): not kept. How
  much a compact, index-based mesh could buy, measured (a build timing each kind of visit, two or three
  runs per scene, both kinds in the same runs): the same rule over plain arrays of rings (the cascade's
  fine level: no CGAL handle read, geometry laid out) against the TIN's own settling passes through
  CGAL's handles, 98 against 111-120 ns a visit (`pile.toml` poured 200 times), 88 against 120-128
  (`flat_stroke.toml` with `tool.depth_m = 0.2`), 88-118 against 80 (trench). During a stroke a visit
  costs 187-189 ns (pile), 226-239 (`flat_stroke.toml`) and 251-256 (trench), of which edge splits, a
  CGAL insertion of 2.0-2.7 us each, are about a fifth (346 splits on the pile, 2029 on the trench). So
  the data structure is at most a quarter of a settled visit (**our code**, not pursued: it could not
  bring the pile's step within 3x the grid's); the rest at rest is the rule's scalar arithmetic over an
  irregular ring (about 700 instructions, against about 40 a node in the grid's eight lanes). Vectorising
  that across a ring was tried (**the method**, measured): one ring per AVX-512 vector (rings of 2 to 8
  neighbours; the fan gradient, the cotangent weights and the excesses in lanes, the ordered sums kept
  scalar so that every height came out bit for bit as before) took the rule from 41 to 32 ns a call in a
  stroke and from 50 to 44 ns at rest on random rings (a micro-benchmark), but in the TIN's visits (the
  ring copied into lanes first, the function compiled for AVX-512 apart from the visit) the steps got
  slower: pile 1.15x, trench 1.02x, `flat_stroke.toml` 1.02x (medians of 9 interleaved rounds, identical
  results). A ring of five to seven neighbours fills few lanes, and the rule is one chain of dependent
  steps (two square roots, five divisions, sums in order) that lanes do not shorten. Not kept. A stroke's
  extra cost is the mesh adapting around the tool (splits, stars re-walked after every stamp): **the
  method**.
- **TIN settling after a deep stroke** (`flat_stroke.toml` with `tool.depth_m = 0.2`): was **our code**,
  fixed. The TIN needed 361k settling updates where the grid needs 97k, because the grid settles with a
  coarse-to-fine cascade and the TIN settled with fine passes only, whose diffusive tail (the last quarter
  of the transfers move a median 7 um each) is long; visiting order did not matter (reversed or
  height-sorted passes: 276k-335k updates). The TIN now has its own cascade (tin/settle_cascade.hpp:
  clusters of vertices in nested cells of the refinement length, the same rule on them, each level's
  change added to its members, then the fine rule over plain arrays at about 700 instructions a visit
  instead of 1500): 136k settling updates, stroke and settling 8.5x the grid's time instead of 16.9x
  (medians of 9 interleaved rounds), the shipped scenes' settling 17-41 % fewer updates, pile RMSE and
  trench walls unchanged (the pile settles from too few active vertices to use it: with it, its RMSE rose
  from 54 to 64 um). What is left is the stroke (tool and erosion during it, two thirds of the TIN's time).
- **Cliffs** (the `cliffs` table): a footprint whose sides are far longer than the mesh's edges (a blade or
  a long spike swept sideways) was **our code**, fixed: its contours' long sides left the band between them
  to slivers as long as a side, and erosion's splits beside the constraints filled the trench with
  sub-millimetre ones, so a 0.2 m spike settled only after 29 M updates (10 s) and a 10 x 60 mm blade not
  at all (facets at 35 degrees); sides are now cut into pieces of at most `tin.refine_m` on both contours
  (about 20k updates each). Swept across the domain's border, such tools also left edges running almost
  along it, which erosion split into chains of slivers against the border (unsettled after 40000 passes,
  facets at 54 degrees): the border now holds like a constraint when an edge is split (1408 passes).
  Erosion's splits beside those long constraints also asked whether a constrained edge's middle lay
  exactly on it by locating the middle, a walk from the last edit, often far along the spike: **our
  code**, fixed (an exact orientation test; the spike's walk steps 119,641 -> 39,712, its erosion
  7.5 -> 6.5 ms and settling 4.2 -> 2.8 ms in single runs, the cliff ratio 12.4x -> 11.2x; the shipped
  scenes have no such edges and run the same). The settling after the stroke kept the last stamp's
  constraints and its contours' O and I pairs, a contour gap apart, whose areas far below their
  neighbours' throttled the last passes (a spike: ten rounds of 64 passes over about 20 vertices,
  6 um a visit): **our code**, fixed: with no tool the last stamp has passed too (constraints dropped,
  contours thinned), the spikes' settling 35,212 -> 9,234 and 29,887 -> 9,341 updates, the other
  strokes' 7-32 % fewer (72 % at a 5-degree angle; trench walls within 0.05 degree of before), and the
  spikes 11.0-11.3x -> 10.0-10.4x the grid's time (7.3-9.9x where the grid runs in AVX2 lanes, 6.9-7.0x
  with this round's step 1e and removal by flips: the cliffs table; interleaved medians of 5 to 7; with two cheaper
  steps of the stamp's bookkeeping, -5 % of its instructions). Linking tcmalloc (Debian's gperftools)
  took them to 9.8x, the trench and `flat_stroke.toml` 3 % faster and the pile 1-3 % slower: not kept
  for so little. A footprint narrower than the mesh resolves was **our
  code**, fixed: a 0.4 mm box was cut into a mesh of 7 mm edges as a hole a hundred times deeper than
  wide, which erosion then filled (58x the grid's time). A footprint narrower than a quarter of
  `tin.refine_m` (4 area / perimeter) now lowers the vertices it covers, as the grid lowers its nodes
  (here none: 0.4x). Measured against the same stroke on a 0.1 mm grid (its surface ends within 0.34 mm
  of flat; rms over the 15 cm square around the stroke, rasters of 0.5 mm), the cut box erred 61 um
  where the flat sand left now errs 6 um (the 5 mm grid: 69 um); a 1.7 mm box: 89 against 40 (111). The ratios that stay above 10x are tools the grid's 5 mm cells
  barely see (a 2 mm box, the narrowest the TIN cuts in, the blade's 10 mm, the spikes' thin ends): there
  the grid moves almost no sand while the TIN cuts the footprint, which is **the method** (the TIN models
  what the grid cannot), not a cost to cut. Of a spike's stamp (callgrind) a quarter goes to dropping the
  last stamp's constraints and thinning its contours, a fifth to inserting the new contours, an eighth
  each to constraining them and to the rim's deposit; CGAL's vertex removals (the thinning's and step
  1e's) are a fifth of it, memory allocation (mostly CGAL's) about a sixth. Moving the band's removals
  before the insertions saved 1.5 % of it and changed the surfaces, so it was not kept. Noticed on the
  way, not pursued: at the default 1 mm tolerance neither back-end models such a stroke closely. Against
  the 0.1 mm grid, cut boxes of 2 to 12 mm err 107-590 um rms on the TIN and 142-437 on the 5 mm grid,
  more than leaving the sand flat would (47-417; a 4 mm box leaves a hump on the TIN where the fine grid
  has a groove 1.4 mm deep), and the paper's 2 cm disk 1231 um on the TIN, 1409 on the grid (flat: 2385;
  single runs of `flat_stroke.toml` with `output.raster_m = 0.0005`): the grooves and rims are a few
  millimetres wide, below both meshes' resolution.
- **TIN pile with the default (gradient) rule**: was **our code**, fixed; what is left is the method at
  this resolution. The pile came out lobed (flank 26.8 degrees, roundness 0.075, RMSE 164 um, 4.7x the
  grid's) although the same sand relaxing from a 35-degree cone ended round: the flow, not the rest state
  (the pile-relaxed table below). Two causes: (1) a transfer was shared among the neighbours in proportion
  to their volume excess, which weights them by their areas, so avalanches ran along the mesh's
  directions (on a regular lattice triangulated one way the pile came out as a ridge, roundness 0.22); it
  is now shared by conductance times excess height, with cotangent weights on a TIN (transport without a
  preferred direction on any triangulation; the regular lattice: 0.05); (2) vertex pairs under a
  millimetre apart throttled the flow (above). Then the flank stood 0.5 degrees below critical (29.4;
  RMSE 55 um): on a cone, whose level lines bend away from the apex, a neighbour sideways of the downhill
  direction lies lower than the slope predicts, and the TIN, which did not cap the drop counted along a
  run (its fan gradient is too smooth a slope to cap by), took that curvature for slope and moved sand
  past rest (**our code**, fixed): where the sand comes to rest the drop is now capped by the steepest
  facet around the vertex (a plane's facets all have its slope; common/erosion.hpp), 54.6 -> 49.8 um,
  flank 29.76 degrees, the relaxed cones 59-69 -> 54-56 um, for a worst single trench section 1.36
  degrees from critical instead of 1.24 and a relaxed plane's steepest facet at 30.9 instead of 30.5
  degrees; capping by the fan gradient, or during the stroke too, lobed the poured pile (80 and 56 um).
  Then pits below the bed outside the pile (14 % of the squared error) and sand off the pour point
  (**our code**, fixed): coarsening at rest gave each removal's volume change back evenly by area over the
  hole's vertices, so mostly to the one with the largest star, on a coarse bed a domain corner, which
  moved sand across the domain (after one pour the sand was centred 13.9 mm from the pour point); each
  hole vertex now takes the removed height over the area it took over (0.7 mm; `tin/simplify.cpp`):
  49.8 -> 47.6 um, over 16 pour points 48.5 -> 44.2 um in the mean, better at every point, no error left
  outside the pile. Then, without refinement at rest (`tin.curvature_tolerance_m = 0`; the pile positions
  table's last columns): RMSE 48 um (1.36x the grid's
  35; over eight pour points within two grid cells, the pile positions table below, 31-55 um against the
  grid's 29-35, 1.49x in the mean, since the grid's pour, fixed below, lands centred between nodes: the
  TIN's error moves by up to 1.8x with where the sand lands relative to its elements, the grid's by 1.2x),
  roundness 0.023, with 339 vertices (0.5x the grid's memory), step 3.8x the grid's (medians of 5
  interleaved rounds; 4.3-4.8x before the grid's pour landed as the same cone as the TIN's, more
  peaked than the even spread it replaced: the grid's step rose 0.044 -> 0.051 ms, the TIN's did not
  move), erosion 94 % of the TIN's stroke time. Where
  the error is (share of the squared error): flank 57 %, toe 37 %, apex 6 % (the grid: 57, 41, 1). Not
  in the mesh: the same mesh with its vertices on the exact cone errs 19 um; its heights err 235 um rms
  on the pile, mostly because the pile stands 0.4 mm off the pour point (its sand's centroid; the cone
  fitted at the best centre errs 38 um, 1.08x the grid's): the transfers on an irregular mesh move the
  sand's centroid, pour after pour, also on a jittered lattice (10^4 initial points: 0.5 mm, 40 um, 22 um
  re-centred). Correcting each transfer's first moment (no sideways component of the sand's motion on a
  slope, none at a peak) took the offset to 0.15 mm but the RMSE to 55 um (flank 29.58 degrees), so
  it was not kept. The flank's deficit before the cap accounted for 18 um. **The method, for the rest**: a piecewise-linear cone on 7 mm edges errs near its apex and toe,
  and the accuracy table's TIN points trade step time for it (refined to 4 mm: 55 um at 2.3x the default
  TIN's step; to 2 mm: 51 um at 5.4x; curvature refinement at 0.2 mm: 35 um at 2.1x, where the grids
  reach 33 um at 2 mm and 28 at 1 mm for a fifth to a quarter of that step time; all settled by the fine
  rule alone, as `pile.toml` now asks, and the ratios vary between runs of the table), none of them below
  the grid's curve. Refining by splitting edges at their middles is itself a cost (**our code**, open): the
  same scene on a TIN started from a regular lattice (`tin.initial_points`, jittered; erosion then has
  nothing to split) rests at 18 um with 2 mm spacing (0.5x the grid's error; 1508 vertices after
  coarsening, step 0.40 ms), where splitting to 2 mm gives 51 um at 1.38 ms (3536 vertices); a 4.2 mm
  lattice steps in 0.12 ms (2.1x the grid's) at 64 um, a 3 mm one in 0.22 ms at 40 um (single runs; a
  5.5 mm lattice came out lobed, 195 um, so the lattice's orientation to the flow matters). The splits'
  mesh has irregular valences and slivers, and its splits (CGAL insertions during the stroke) are a fifth
  of the stroke's erosion time. A refinement that inserts the points of a regular lattice where sand
  flows, instead of edge middles, is the next lever on the pile's step and error; a lattice over the
  whole domain from the start costs memory (0.4-3.8 MB against the grid's 0.16).
  The TIN's own way out, refining only the surface at rest (`tin.curvature_when = "settling"`, "tin curved
  0.2 mm at rest" in the accuracy table): its steps cost what the default TIN's do (the tool's steps are
  not at rest), and it ends at 37 um (1.05x the grid's) at `tin.curvature_tolerance_m = 0.0002`, with
  550 vertices, 0.72x the grid's final and 1.12x its peak memory, settling 3.3x the default TIN's time;
  at 0.0003-0.001 at 40-44 um (1.15-1.25x) with peak memory 0.73-0.94x the grid's (single runs, after
  the removals' give-back above). As a default it would not pay elsewhere: on the relaxed cone, the
  trench, the ridge and the plane it changes the error by -0.03 to +0.01 degrees or +-0.5 um, for
  1.1-5x the settling time (the plane's 0.77 -> 1.54 s, the heightmap's 3-5x) and up to 1.2x the memory.
  It is a choice of accuracy against memory and settling time that the default leaves to the scene, and
  `pile.toml`, the accuracy reference, now makes it, at `tin.curvature_tolerance_m = 0.0005` (the
  pile-relax and pile positions tables have this run's figures): at the scene's pour point RMSE 40.6 um
  (1.16x the grid's), 419 vertices, peak memory 0.83x the grid's, settling 2.5-4.2x the grid's time
  (single and interleaved runs on the AVX2 machine), the pours' steps the same work as without it
  (27,021 erosion updates either way); over the eight pour points 1.27x in the mean, 0.98-1.56x
  (1.49x without; the pile positions table; at 0.0003 in single runs 1.18x, but settling 5.7x). With
  the paper's edge rule it does not help (the regression golden's pile: 70.8 -> 72.5 um, flank
  30.70 -> 31.22 degrees). The pile's bars (RMSE <= 1.25x, memory <= 1x, settling <= 10x, step <= 3x
  the grid's) then hold together where the grid runs in AVX2 lanes (the bars table; during development
  the step 2.2-3.2x in four interleaved runs of 7 to 9 rounds on a noisy machine, single rounds 1.7-4.0x:
  at the bar), not where it runs in AVX-512 lanes (3.8x): the step is the method's cost per visit against the grid's vector lanes (above); the
  error is the TIN's own refinement at rest.
- **TIN on a narrow domain** (found by running the shipped scenes on random domains): was **our code**,
  fixed. A pile poured on a 0.3 x 0.01 m strip never settled on the TIN (facets at 88 degrees after
  20000 settling passes, 127 M updates, 12 s; 0.02 m wide: 290 M, 32 s) where the grid settles at once:
  the strip's first diagonal lies 1.9 degrees from the border, and halving edges at such angles again
  and again put vertices microns from the border, the apices of slivers whose near-zero areas
  throttled every transfer. A split's middle closer to the border than 2 % of the edge's length (as
  beside a constraint) now goes onto it: 137 k updates, 0.01 s (`tests/unit/tin_border_test.cpp`); the
  shipped scenes are unchanged. Domains narrower than the tool or the refinement length (3-10 mm
  wide strips under 8-40 mm tools) still end unsettled on the TIN (3-60 degrees of excess after 20000
  passes, said on stderr), before and after this change; not pursued.
- **Grid pour between nodes**: was **our code**, fixed. The grid spread a pour's sand evenly over the
  nodes within the pour radius, which on 2.5 mm cells are a handful whose centroid lies up to 0.6 mm
  from a pour point between nodes (0.2-1.7 mm in the unit test's cases), and the pile grew there: at
  the seven points between nodes of the pile positions table the grid erred 29-52 um (29 re-centred).
  The sand now lands as a cone of the pour radius (as on the TIN) handed to the nodes by their bilinear
  weights, which reproduce linear functions, so its centroid is the pour point
  (`grid/stamp_kernel.hpp`): 29-31 um at those points, the scene's point (a node) unchanged at 35 um,
  and the sparse grid the same. Both back-ends now receive the same sand in the same shape; the cone
  is more peaked than the even spread, so the grid's pile step rose 0.044 -> 0.051 ms (interleaved,
  5 rounds).
- **TIN initial surface** (dunes, cones, heightmaps): was **our code**, fixed. Greedy insertion to
  `tin.tolerance_m` interpolated the terrain at the vertices, which errs to one side wherever the
  terrain bends (the chords of a cone's circular level lines lie inside it): `cone.toml`'s TIN held
  2.7 % less sand than the terrain (1.944e-5 against 2e-5 m^3 at 35 degrees, 2.1-2.6 % at 45 and 60),
  so the relaxed cones were measured against sand they never had. The vertices now take the terrain's
  L2 projection onto the same mesh (`tin/project.cpp`): its volume to 6e-7 of the sand, the initial
  cone's RMSE 65 -> 44 um, dunes on 3000 initial points 124 -> 63 um, planes exact, for 0.9 s more to
  build 10^6 initial points of dunes. With the right sand the relaxed cones (the pile-relax table) end
  at 43-50 um against the grid's 20-34 (before: 52, 45, 40 um at 35, 45, 60 degrees: at 45 and 60
  degrees the missing sand had hidden the rest): their flanks stand 0.1-0.3 degrees below critical and
  their foot lies 1.0-1.2 mm wider than the grid's, the toe's slope break spread over the 3-6 mm edges
  there (**the method** at this resolution; curvature refinement at rest narrows it, see the pile).
- **TIN curvature refinement on trenches** (`tin.curvature_tolerance_m = 0.0003`; "tin curved" is now 0.0002): was
  **our code**, fixed. Eight of its nine trench runs per rule in the orientation table ended unsettled
  after the 20,000 settling passes, with facets near 90 degrees, and their wall angles were those of a
  surface still moving. Curvature splits of edges lying almost along the last stamp's contours put
  vertices a hair beside a constraint: chains of slivers that the constraints kept, whose vertices of
  near-zero area capped every transfer of their neighbours (the cotangent split gives no pair more than f
  times its excess) to a trickle. Such an edge now stays whole; every run settles, and the default TIN's
  runs are unchanged bit for bit. (Sharing the capped rest among the other neighbours also settled them,
  but made the pile worse, RMSE 53 -> 71 um; capping the cotangents did not settle them.)
- **TIN simplification**: was **our code** (the paper's step 3 never removed a vertex on a flat bed), fixed:
  once the terrain is at rest, near-planar vertices are removed (volume kept, no triangle tilted past the
  stable slope), tens per shipped scene; during strokes the paper's alpha_flat rule alone acts. On large
  TINs that scan was **our code** too, fixed: each removal located its vertex by walking from wherever the
  last edit had left the walk, O(sqrt(n)) faces (`flat_stroke.toml` on 10^6 initial points, 974k
  removals: 441 M walk steps, settling 18.5 s of a 22.3 s run); it now starts at the vertex (1.8 M steps,
  11 s). And the runner integrated the TIN's surface after every phase (23 % of those 11 s): the TIN now
  reports each phase's volume change from its own bookkeeping. The run takes 7.2 s, settling 5.8 s.
- **TIN trench walls**: the paper's edge rule leaves them 1-4 degrees steeper than critical (a triangle
  whose edges are all stable can stand steeper); the gradient rule brings their mean to within 0.1
  degree of critical at every azimuth (orientation table): **the rule**, now fixed by default. Single
  cross-sections still stray up to 1.1 degrees on the default mesh (0.4-0.55 with curvature refinement at
  0.2 mm, the orientation table's "tin curved"; which section is worst moves with the order of the Delaunay
  flips on the tool's co-circular contour points, so single figures move by ~0.1 degree between versions
  that change no rule; 0.65 at 0.3 mm; at about 2.7x the TIN's step time): **the method's resolution**.
- **TIN memory**: **the method**. A vertex with its triangles costs about 170 bytes against a grid node's
  10, so the TIN wins only where it needs about 17 times fewer elements than a grid of the same accuracy.
- **Grid speed**: was **our code**, now near the method's limit in double. The dense pass skips stable
  nodes by bit scans over vector-classed rows and visits up to eight independent nodes at once (columns
  modulo 3; AVX-512 lanes with masked ends, AVX2 lanes (four) and SSE2 where the CPU lacks them, the
  gradient rule included), bit for bit the scalar visits; rows are classed only where that pays, the active set is updated a
  word at a time, and the AVX-512 pass is compiled as one function (visits, classing and set update
  inlined into the row loop): on `grid_bench`'s states 102-104 M updates/s on the pile and 158-160 M on
  the stroke (36-51 five rounds ago, 82 and 126 at the start of the last round), 194-197 M with every node of 2048^2
  active (162 then), 12.5x a plain scalar sweep of the same rule (interleaved medians, +-5 %
  between runs). On one core that meets the 100 M on the pile, not the 250 M all active. A large dense
  pass (2^16 nodes in 32 rows or more) now runs as two bands of rows and the two-row seam between them
  (rows three apart touch disjoint rows, so the bands may run at once; the seam goes after, and the
  heights are the same bit for bit on one thread or two): with `grid.threads = 2` (`grid_bench`'s
  `BM_AllActiveTwoThreads`, double) 316-349 M updates/s of wall time with every node of 2048^2 active
  (medians of 7 in two runs, the lower with another job on the machine), 1.7-1.8x one thread's 191-193
  and 21-22x the scalar sweep, for about the same CPU time (87-93 ms for 4 passes against 87). The comparison runs `grid.threads = 1`, so that the grid is timed on one core as the TIN is;
  float runs its bands one after the other (its rounding carry chains the writes). Tried and measured, not
  kept (ratios pile / stroke / all active): keeping a chunk of a row in registers across its three
  column phases, which saves the permutes that gather a 3 x 3 block per lane but makes each chunk wait
  for the one before (0.94 / 0.92 / 0.67); splitting the rows by column modulo 3 once per row (0.93 /
  0.93 / 0.85); fewer vector operations per group, balanced sums, unmasked loads and stores, deferred
  flags (0.88-1.02). A diagnostic build without the groups' stores (wrong heights) ran 1.01 / 1.23 /
  1.13, so on long rows about a sixth of the time goes with the stores; rows 4 KiB apart (power-of-two
  widths) are not the cause (510 and 2046 nodes wide: 0.99 / 0.99 / 1.02). What stops it short: the
  in-place (Gauss-Seidel) order that the default transfer fraction needs to stay monotone (a Jacobi or
  four-colour sweep overshoots at f = 0.5), whose independent visits are a column phase's, and, in
  float, the rounding carry that chains every transfer to the one before: **the method's order** on
  this machine, as far as our measurements go. The order is the faster way to rest, not only the
  monotone one: a vectorised two-pass (Jacobi) sweep at its monotone fraction 2/9 (`grid_bench`'s
  `BM_JacobiSweep`, every node each pass) runs 137 M updates/s on the all-active state against the
  kernel's 191 (interleaved medians of 5), and takes the 512^2 dunes to rest with fine passes in 6968
  passes, 1.83 G updates and 10.4 s, against 2457 passes, 0.40 G updates and 2.1 s (`BM_Settle*`, one
  run each): a Jacobi sweep three times as fast would still need 4.5 s. An updates-per-second bar
  rewards the sweep that settles later.
- **Grid settling of large grids**: was **our code**, fixed. Fine passes alone are diffusive (passes grow
  about 3.5x per halving of the cell, time as n^1.9); a coarse-to-fine cascade relaxes 2 x 2 blocks of
  blocks with the same kernel, adds each level's change to its children (exact volume, energy never
  rising) and lets the fine passes finish: see the settling table below for this run's figures.
- **Settling cascades on a spreading pile** (both back-ends): **our code**, not fixed; made a scene's choice.
  The cascades (the grid's, and the TIN's clusters) add each coarse level's change to its members as a
  constant; where a pile spreads over many cells onto flat ground, that throws sand past where the fine
  rule would rest it, and the rule, which moves sand only downhill, never takes it back. The accuracy
  table showed the grid's pile worse at 1 mm cells than at 2 mm (107 against 33 um) for that reason alone:
  with the fine rule alone it is 28 um at 1 mm and 25 at 0.5 mm, for 6.6x and 8.9x the settling time; a
  TIN of 10^5 initial points went from 11 to 207 um (flank 26.6 instead of 30.0 degrees) for half the
  time. Not always in that direction: on the TIN refined to 2 mm only where the sand flows, the cascade's
  pile came out closer to the cone (37 against 51 um). Trench walls, which sand falls from rather than
  spreads over, keep their angle within 0.05 degrees either way. `erosion.cascade` now chooses; `pile.toml`, the accuracy reference, settles without
  it, the stroke scenes with it (the cascade table below has both).
- **Sparse grid on the trench** (memory 0.39x the dense grid's, not a fifth): **the method**. Memory
  follows the disturbed area in whole 8 x 8 blocks at 8.6 bytes per node; a long trench disturbs about a
  quarter of the nodes. Its step was 2-3.5x the dense grid's because its dense pass visited nodes one at a
  time (**our code**): it now runs each row on a contiguous copy of the three rows it touches, with the
  dense grid's vector classing and lanes (same heights bit for bit); the window now slides (each row read
  and written back once a pass instead of three times: trench erosion 125 -> 103 M instructions against
  the dense grid's 96 M; `sparse_bench` step ratios 1.43-1.58 -> 1.26-1.34 on the five shipped scenes).
  Before that it cost 1.4-1.7x the dense grid's step on the shipped scenes.
- **4-neighbour grid**: with the edge rule a pile is a diamond and trench walls stand at 39 degrees at 45
  degrees azimuth; the gradient rule removes the trench's anisotropy but leaves piles and planes up to
  2 degrees flatter than critical, because sand cannot leave along the diagonal: **the method's stencil**.
- **TIN stability and reproducibility** (a stroke leaving the domain never settled; two runs differed in
  their last digits): **our code**, fixed (border crossings snapped to existing border vertices; no order
  follows memory addresses). Nor does a TIN run depend any more on being observed (**our code**, fixed):
  the queries made between steps (the runner's energy and metric rasters, renders, haptic patches) walked
  from the same hint, with the same random edge order, as the stamps and erosion, whose walks decide ties
  (a point on an edge, cocircular vertices), so `output.energy = true` changed what `pile.toml` built
  (RMSE 54.7 against 53.9 um without it); queries now walk apart
  (tests/unit/tin_reproducible_test.cpp), and every TIN figure here is the unobserved run's.
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--sandbench", default=str(sbrun.ROOT / "build/release/harness/sandbench"))
    ap.add_argument("--results", default=str(sbrun.ROOT / "results"))
    ap.add_argument("--profile", default="paper", choices=sbrun.PROFILES)
    ap.add_argument("--full", action="store_true", help="the 'full' profile: sizes up to 1e6 vertices")
    ap.add_argument("--only", nargs="*", choices=EXPERIMENTS, help="run only these experiments")
    ap.add_argument("--jobs", type=int, default=2, help="local engine: runs at once")
    ap.add_argument("--engine", choices=["local", "slurm"], default="local",
                    help="local: a pool on this machine; slurm: a job array through sbatch")
    slurm = ap.add_argument_group("slurm engine (sbatch's defaults and SBATCH_* variables apply otherwise)")
    slurm.add_argument("--partition")
    slurm.add_argument("--account")
    slurm.add_argument("--time", help="time limit of one array task, sbatch syntax (e.g. 00:30:00)")
    slurm.add_argument("--mem", help="memory of one array task, sbatch syntax (e.g. 4G)")
    slurm.add_argument("--parallel", type=int, default=32, help="array tasks at once (the %%N throttle)")
    slurm.add_argument("--batch", type=int, default=1, help="runs per array task")
    slurm.add_argument("--sbatch-arg", action="append", default=[], help="one more sbatch argument (repeatable)")
    slurm.add_argument("--poll", type=float, default=5.0, help="seconds between squeue polls")
    args = ap.parse_args()
    sbrun.env_ok()
    engine = None
    if args.engine == "slurm":
        engine = engines.SlurmEngine(args.partition, args.account, args.time, args.mem, args.parallel, args.batch,
                                     args.sbatch_arg, args.poll)
    ctx = sbrun.Context(args.sandbench, args.results, "full" if args.full else args.profile, args.jobs, engine)
    ctx.defer = True
    names = args.only or list(EXPERIMENTS)
    sbrun.progress(f"reproduce: {len(names)} experiments, profile {ctx.profile_name}, {ctx.engine.name} engine, "
                   f"binary {ctx.binary['version']}")
    start = time.monotonic()
    sections = run_experiments(ctx, names)
    cpu = resource.getrusage(resource.RUSAGE_CHILDREN)
    sbrun.progress(f"reproduce: {time.monotonic() - start:.0f} s wall, {cpu.ru_utime + cpu.ru_stime:.0f} s CPU in "
                   f"processes run on this machine")
    if engine is not None:
        sbrun.progress(f"slurm: waited for job arrays {' '.join(engine.job_ids) or '(none: every run was done)'}")

    if args.only:  # a partial run prints its sections; only a full run writes REPORT.md
        print("\n".join(sections))
        return
    report = ("# sandbench: reproducing Purchart's TIN sand model\n\n" + machine_header(ctx) + "\n" + INTRO + "\n" +
              METHOD_OR_CODE + "\n" +
              "\n".join(sections))
    tmp = ctx.results / "REPORT.md.tmp"
    tmp.write_text(report)
    tmp.replace(ctx.results / "REPORT.md")
    sbrun.progress(f"wrote {ctx.results / 'REPORT.md'}")


if __name__ == "__main__":
    main()
