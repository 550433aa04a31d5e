// Splitting one run over several machines (`run --shard K/N`) and joining the parts
// again (`rastercheck merge`). The split is a pure function of the whole run (its
// fixtures, backends and their expected costs), so every shard computes the same plan
// on its own, with no coordination; each shard's report.json records its part of the
// plan, and merge puts the rows back in the order the unsharded run has.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/report.h"
#include "fixtures/scene.h"

namespace rc {

// Shard `index` (1-based) of `count`.
struct ShardSpec {
  int index = 1;
  int count = 1;
};

// "K/N" with 1 <= K <= N, or "env": from the environment (shardFromEnvironment). Throws
// InputError naming the option and what is wrong.
ShardSpec parseShard(std::string_view text);

// The first of: RASTERCHECK_SHARD=K/N; GitLab CI's CI_NODE_INDEX (1-based) and
// CI_NODE_TOTAL (`parallel: N`); a Kubernetes Indexed Job's JOB_COMPLETION_INDEX (0-based)
// with the completions count in JOB_COMPLETIONS (set it from the Job's spec; Kubernetes
// does not). Throws InputError when none is set or a value is malformed.
ShardSpec shardFromEnvironment();

// The expected cost of rasterizing a fixture, in units of one pixel's shading on llvmpipe
// (comparable between fixtures): pixels x (1 + lights / 2) + 50 x triangles.
double rasterCost(const Scene& scene);
// How long a backend takes for the same fixture, relative to llvmpipe (softpipe
// rasterizes on one thread with no JIT; the reference is scalar but has no driver).
double backendWeight(std::string_view spec);
// The expected cost of one render of a fixture with raster cost `raster` by `spec`: a
// fixed part per render plus the weighted rasterization (docs/scaling.md).
double renderCost(double raster, std::string_view spec);

// One pair of the whole run: its fixture and the cost of its own render (the actual
// backend); `shared` below is the cost of the renders every pair of a fixture needs
// (--against and the reference).
struct ShardUnit {
  std::size_t fixture = 0;
  double cost = 0.0;
};

// 0-based shard of every unit: largest first to the shard that ends least loaded, where a
// shard that already renders the unit's fixture does not pay its shared renders again.
// Deterministic: ties go to the earlier unit and the lower shard.
std::vector<int> assignShards(const std::vector<ShardUnit>& units,
                              const std::vector<double>& shared, int count);

// A digest (16 hex digits) of everything the plan depends on, so that merge can tell
// shards of one run from shards of different runs.
std::string planDigest(const std::vector<std::string>& parts);

// The report of a sharded run joined again. Every input must be a shard of the same plan
// (count and digest) and every shard must be there once; or, when none is a shard, the
// reports are concatenated in the order given. Rows come back in the whole run's order;
// `variants` is the union (the first shard's entry per backend). The rows' image paths
// still point into the input folders (files_from); the caller moves them.
struct MergedRuns {
  Report report;
  int shards = 0;  // 0: the inputs were not shards
};
MergedRuns mergeRunReports(const std::vector<std::filesystem::path>& run_dirs);

}  // namespace rc
