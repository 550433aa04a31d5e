// The rastercheck subcommands. Each returns the process exit code (fixtures/errors.h)
// and throws InputError / BackendError for the caller to report in one line.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rc {

struct RenderArgs {
  std::filesystem::path scene;
  std::string backend = "ref";
  std::filesystem::path out;
  bool all_passes = false;  // multi-pass scenes: every pass's target in OUT/passes/K-NAME/
};
int renderCommand(const RenderArgs& args);

struct GenerateArgs {
  std::string seed;         // 0 .. 2^64 - 1, decimal (checked here: CLI11 wraps "-1")
  std::string first = "0";  // index of the first fixture, same range
  std::int64_t count = 100;
  std::filesystem::path out;
  std::string max_size = "200x150";  // WxH
  std::string profile = "all";
  std::filesystem::path meshes;  // empty: /usr/share/assimp/models
};
int generateCommand(const GenerateArgs& args);
struct RandomSceneOptions;
// The generator's options from the arguments, checked (InputError names the option).
RandomSceneOptions generateOptions(const GenerateArgs& args);

struct ListArgs {
  std::vector<std::filesystem::path> paths;
  bool json = false;
  bool markdown = false;
};
int listCommand(const ListArgs& args);

}  // namespace rc

namespace rc {

// `--tolerance CLASS.KEY=VALUE` arguments are parsed by compare/pair_tolerances.h.

struct CompareArgs {
  std::filesystem::path expected;
  std::filesystem::path actual;
  std::filesystem::path uncertainty;  // empty: the expected (or actual) frame's channels
  std::filesystem::path out;
  std::vector<std::string> tolerance;
  bool diff_exr = false;  // write diff.exr also when the pair passes
  bool flip = false;      // compute LDR-FLIP (report.json "flip", flip_heat.png)
  std::optional<double>
      flip_threshold;  // a pair whose mean LDR-FLIP exceeds it fails (implies flip)
};
int compareCommand(const CompareArgs& args);

struct RunArgs {
  std::vector<std::filesystem::path> inputs;  // fixtures or folders (default: the catalog)
  std::vector<std::string> backends;
  std::string against = "ref";
  std::filesystem::path out;
  std::vector<std::string> tolerance;
  bool flip = false;                     // as for compare
  std::optional<double> flip_threshold;  // as for compare
  int jobs = 0;                          // 0: one per core
  bool variants = true;                  // probe each GL backend's variants (app/variants.h)
  double timeout_seconds = 120.0;        // per render: a worker past it is killed (0: no watchdog)
  bool keep_frames = false;              // frames and pair images of passing pairs too
  std::string shard;                     // "K/N" or "env"; empty: the whole run
  // Known driver differences to mark (compare/expectations.h): a file, "none", or empty
  // for the default (defaultExpectationsFile()).
  std::string expectations;
  // Renders again, each in a fresh worker, of every GL pair that fails or errors; a pair
  // whose renders disagree is a flake. -1: the default (1 for GL backends; the reference is
  // deterministic and never retried).
  int retries = -1;
  // deqp-runner's files (compare/deqp_results.h, docs/ci.md); empty: none.
  std::filesystem::path baseline, flakes, skips;
  // deqp-runner's caselist: one fixture name per line, the run's fixtures and their order;
  // and its sharding: every fraction-th fixture from the fraction_start-th (1-based).
  std::filesystem::path caselist;
  int fraction = 1;
  int fraction_start = 1;
};
int runCommand(const RunArgs& args);

// `rastercheck worker --backend SPEC`: hidden; `run` starts it (app/worker.h).
int workerCommand(const std::string& spec);

struct MergeArgs {
  std::vector<std::filesystem::path> runs;  // folders written by `run --shard K/N`
  std::filesystem::path out;
  std::filesystem::path baseline, flakes, skips;  // as for run
};
int mergeCommand(const MergeArgs& args);

struct DiffRunsArgs {
  std::filesystem::path old_run;
  std::filesystem::path new_run;
  bool json = false;          // print JSON instead of text
  std::filesystem::path out;  // also write diff.json, diff.txt and diff.html there
};
int diffRunsCommand(const DiffRunsArgs& args);

struct AccuracyArgs {
  std::vector<std::filesystem::path> runs;      // folders written by `run`
  std::vector<std::filesystem::path> catalogs;  // where to find fixtures by name (tags)
  std::filesystem::path expectations;           // known differences to list (optional)
  std::filesystem::path out;                    // empty: stdout
  std::string command;                          // how the document says it was made
};
int accuracyCommand(const AccuracyArgs& args);

struct ExplainArgs {
  std::filesystem::path scene;
  std::string pixel;                  // "X,Y" in image coordinates (origin top-left)
  std::vector<std::string> backends;  // compared with the reference at that pixel
  std::string reference = "ref";      // the reference SPEC whose pixel history is told
  std::vector<std::string> tolerance;
  bool json = false;
};
int explainCommand(const ExplainArgs& args);

struct ReduceArgs {
  std::filesystem::path scene;
  std::string expected;
  std::string actual;
  std::filesystem::path out;
  std::string failure_class;  // visibility|depth|shading; empty: the first that fails
  double timeout_seconds = 300.0;
  std::vector<std::string> tolerance;
};
int reduceCommand(const ReduceArgs& args);

struct CampaignArgs {
  std::string seed;  // as for generate
  std::int64_t count = 100;
  std::string profile = "all";
  std::string max_size = "200x150";
  std::filesystem::path meshes;
  std::vector<std::string> backends;
  std::string against = "ref";
  std::filesystem::path out;
  std::vector<std::string> tolerance;
  double reduce_seconds = 60.0;  // per failure; 0: do not reduce (probe the original)
  int jobs = 0;                  // 0: one per core
  int batch = 20;                // scenes per `run`
  // Known driver differences for the `run` children (as run --expectations): a file,
  // "none", or empty for the default (fixtures/expectations.json).
  std::string expectations;
  bool mutations = false;           // the mutation study instead of a failure campaign
  std::vector<std::string> faults;  // --mutations: the faults to inject (default: all)
  std::string command_line;         // as typed, for the summary
};
int campaignCommand(const CampaignArgs& args);
int mutationCampaign(const CampaignArgs& args);

}  // namespace rc
