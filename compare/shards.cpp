// See shards.h.
#include "compare/shards.h"

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <map>
#include <numeric>
#include <set>

#include <fmt/format.h>

#include "compare/report_read.h"
#include "fixtures/errors.h"

namespace rc {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

int parseInt(std::string_view text, bool& ok) {
  int v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  ok = !text.empty() && ec == std::errc() && end == text.data() + text.size();
  return v;
}

const char* env(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? v : nullptr;
}

ShardSpec checked(int index, int count, const std::string& source) {
  if (count < 1 || index < 1 || index > count)
    throw InputError(
        fmt::format("{}: shard {} of {} does not exist (need 1 <= K <= N)", source, index, count));
  return {index, count};
}

}  // namespace

ShardSpec parseShard(std::string_view text) {
  if (text == "env") return shardFromEnvironment();
  const std::size_t slash = text.find('/');
  bool ok_k = false;
  bool ok_n = false;
  const int k = slash == std::string_view::npos ? 0 : parseInt(text.substr(0, slash), ok_k);
  const int n = slash == std::string_view::npos ? 0 : parseInt(text.substr(slash + 1), ok_n);
  if (!ok_k || !ok_n)
    throw InputError(fmt::format("--shard '{}': expected K/N (e.g. 2/8) or env", text));
  return checked(k, n, fmt::format("--shard {}", text));
}

ShardSpec shardFromEnvironment() {
  if (const char* s = env("RASTERCHECK_SHARD")) {
    if (std::string_view(s) == "env") throw InputError("RASTERCHECK_SHARD: must be K/N, not env");
    try {
      return parseShard(s);
    } catch (const InputError& e) {
      throw InputError(fmt::format("RASTERCHECK_SHARD: {}", e.what()));
    }
  }
  auto number = [](const char* name, const char* value) {
    bool ok = false;
    const int v = parseInt(value, ok);
    if (!ok) throw InputError(fmt::format("{}='{}': not an integer", name, value));
    return v;
  };
  // GitLab CI `parallel: N`: CI_NODE_INDEX 1..N; without `parallel`, CI_NODE_TOTAL is 1.
  if (const char* total = env("CI_NODE_TOTAL")) {
    const int n = number("CI_NODE_TOTAL", total);
    const char* index = env("CI_NODE_INDEX");
    const int k = index ? number("CI_NODE_INDEX", index) : 1;
    return checked(k, n, "CI_NODE_INDEX/CI_NODE_TOTAL");
  }
  // Kubernetes Indexed Job: JOB_COMPLETION_INDEX 0..completions-1.
  if (const char* index = env("JOB_COMPLETION_INDEX")) {
    const char* total = env("JOB_COMPLETIONS");
    if (!total)
      throw InputError(
          "--shard env: JOB_COMPLETION_INDEX is set but JOB_COMPLETIONS is not (set it to the "
          "Job's spec.completions)");
    return checked(number("JOB_COMPLETION_INDEX", index) + 1, number("JOB_COMPLETIONS", total),
                   "JOB_COMPLETION_INDEX/JOB_COMPLETIONS");
  }
  throw InputError(
      "--shard env: none of RASTERCHECK_SHARD, CI_NODE_INDEX/CI_NODE_TOTAL (GitLab CI) or "
      "JOB_COMPLETION_INDEX/JOB_COMPLETIONS (Kubernetes Indexed Job) is set");
}

double rasterCost(const Scene& scene) {
  // Per pixel one more shading pass per two lights; per triangle setup worth ~50 pixels.
  constexpr double kPerTriangle = 50.0;
  std::size_t triangles = 0;
  for (const Object& o : scene.objects) triangles += o.mesh.triangles.size();
  const double pixels = static_cast<double>(scene.width) * scene.height;
  return pixels * (1.0 + 0.5 * static_cast<double>(scene.lights.size())) +
         kPerTriangle * static_cast<double>(triangles);
}

double backendWeight(std::string_view spec) {
  // Mean render times on 120 fixtures up to 200x150 (docs/performance.md): reference
  // 2.6 ms, llvmpipe 7.2 ms, softpipe 56 ms; other GL drivers are taken as llvmpipe.
  if (spec.substr(0, 3) == "ref") return 0.5;
  if (spec.find("softpipe") != std::string_view::npos) return 6.0;
  return 1.0;
}

double renderCost(double raster, std::string_view spec) {
  // What a render costs besides rasterizing, whatever the backend: loading the fixture,
  // moving the frame, comparing it (~1-2 ms, worth ~5,000 pixels of llvmpipe's work).
  constexpr double kPerRender = 5000.0;
  return kPerRender + backendWeight(spec) * raster;
}

std::vector<int> assignShards(const std::vector<ShardUnit>& units,
                              const std::vector<double>& shared, int count) {
  std::vector<int> out(units.size(), 0);
  if (count <= 1) return out;
  std::vector<std::size_t> order(units.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return units[a].cost > units[b].cost; });
  std::vector<double> load(static_cast<std::size_t>(count), 0.0);
  std::vector<std::vector<bool>> has(static_cast<std::size_t>(count),
                                     std::vector<bool>(shared.size(), false));
  for (const std::size_t u : order) {
    const ShardUnit& unit = units[u];
    int best = 0;
    double best_load = 0.0;
    for (int s = 0; s < count; ++s) {
      const auto k = static_cast<std::size_t>(s);
      const double after =
          load[k] + unit.cost + (has[k][unit.fixture] ? 0.0 : shared[unit.fixture]);
      if (s == 0 || after < best_load) {
        best = s;
        best_load = after;
      }
    }
    out[u] = best;
    load[static_cast<std::size_t>(best)] = best_load;
    has[static_cast<std::size_t>(best)][unit.fixture] = true;
  }
  return out;
}

std::string planDigest(const std::vector<std::string>& parts) {
  std::uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a, 64 bits
  for (const std::string& p : parts) {
    for (const char c : p) {
      h ^= static_cast<unsigned char>(c);
      h *= 0x100000001b3ull;
    }
    h ^= 0xffu;  // separator
    h *= 0x100000001b3ull;
  }
  return fmt::format("{:016x}", h);
}

MergedRuns mergeRunReports(const std::vector<fs::path>& run_dirs) {
  if (run_dirs.empty()) throw InputError("merge: needs at least one run folder");
  struct Part {
    fs::path file;
    Report report;
  };
  std::vector<Part> parts;
  for (const fs::path& dir : run_dirs) {
    const fs::path file = dir / "report.json";
    parts.push_back({file, readReportFile(file)});
  }
  MergedRuns out;
  out.report.tool_name = parts.front().report.tool_name;
  out.report.tool_version = parts.front().report.tool_version;
  out.report.command = parts.front().report.command;

  const bool sharded = !parts.front().report.shard.empty();
  for (const Part& p : parts) {
    if (p.report.shard.empty() != sharded) continue;
    throw InputError(fmt::format("{}: {} a shard, but {} {}", p.file.string(),
                                 sharded ? "is not" : "is", parts.front().file.string(),
                                 sharded ? "is" : "is not"));
  }
  // Tests --skips left out: every part lists those of its fixtures (each once here).
  std::set<std::string> skipped;
  for (const Part& p : parts)
    for (const std::string& s : p.report.skipped)
      if (skipped.insert(s).second) out.report.skipped.push_back(s);
  if (!sharded) {
    for (Part& p : parts) {
      for (PairResult& r : p.report.results) out.report.results.push_back(std::move(r));
      for (const auto& [spec, v] : p.report.variants.items())
        if (!out.report.variants.contains(spec)) out.report.variants[spec] = v;
    }
    return out;
  }

  // Shards: all of one plan, each once; rows back at their places in the whole run.
  auto field = [](const Part& p, const char* key) -> const json& {
    const ReportReader r(p.file);
    const json& v = r.member(p.report.shard, key, "shard");
    if (std::string(key) == "pair_indices" ? !v.is_array()
                                           : !(v.is_number_integer() || v.is_string()))
      r.fail(std::string("shard.") + key, "has the wrong type");
    return v;
  };
  const json& count_j = field(parts.front(), "count");
  const json& plan = field(parts.front(), "plan");
  const json& total_j = field(parts.front(), "pairs");
  if (!count_j.is_number_integer() || !total_j.is_number_integer())
    ReportReader(parts.front().file).fail("shard", "count and pairs must be integers");
  const int count = count_j.get<int>();
  const auto total = total_j.get<std::size_t>();
  std::map<int, const Part*> by_index;
  for (const Part& p : parts) {
    const ReportReader r(p.file);
    if (field(p, "count") != count_j || field(p, "plan") != plan || field(p, "pairs") != total_j)
      r.fail("shard", fmt::format("not a shard of the same run as {} (other plan, count or size)",
                                  parts.front().file.string()));
    const json& index_j = field(p, "index");
    if (!index_j.is_number_integer()) r.fail("shard.index", "must be an integer");
    const int index = index_j.get<int>();
    if (!by_index.emplace(index, &p).second)
      r.fail("shard.index", fmt::format("shard {} of {} is given twice", index, count));
    if (field(p, "pair_indices").size() != p.report.results.size())
      r.fail("shard.pair_indices", "does not match results");
  }
  for (int k = 1; k <= count; ++k)
    if (!by_index.count(k))
      throw InputError(fmt::format("merge: shard {}/{} is missing (plan {})", k, count,
                                   plan.is_string() ? plan.get<std::string>() : plan.dump()));
  std::vector<std::optional<PairResult>> rows(total);
  for (auto& [index, part] : by_index) {
    Part& p = const_cast<Part&>(*part);
    const json& indices = field(p, "pair_indices");
    for (std::size_t i = 0; i < indices.size(); ++i) {
      const json& at = indices[i];
      if (!at.is_number_unsigned() || at.get<std::size_t>() >= total ||
          rows[at.get<std::size_t>()].has_value())
        ReportReader(p.file).fail(fmt::format("shard.pair_indices[{}]", i),
                                  "out of range or given twice");
      rows[at.get<std::size_t>()] = std::move(p.report.results[i]);
    }
    for (const auto& [spec, v] : p.report.variants.items())
      if (!out.report.variants.contains(spec)) out.report.variants[spec] = v;
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (!rows[i]) throw InputError(fmt::format("merge: pair {} of {} is in no shard", i, total));
    out.report.results.push_back(std::move(*rows[i]));
  }
  out.shards = count;
  return out;
}

}  // namespace rc
