// See cli.h. Options are declared as data with help text (idiff style); every failure
// ends as one line on stderr and an exit code from fixtures/errors.h.
#include "app/cli.h"

#include <cstdlib>
#include <iostream>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "app/version.h"
#include "debug/campaign.h"
#include "fixtures/errors.h"
#include "fixtures/message_text.h"
#include "fixtures/resource_estimate.h"

namespace rc {
int runCli(int argc, char** argv) {
  CLI::App app{
      "rastercheck: renders fixtures with a scalar CPU reference and with OpenGL drivers, and "
      "says per pixel where and why they disagree.\n"
      "Exit codes: 0 pass (warnings allowed), 1 a comparison failed, 2 bad input or usage, "
      "3 a backend could not run."};
  app.set_version_flag("--version", std::string("rastercheck ") + kVersion);
  app.require_subcommand(1);
  // Usage errors in one line, as every other error (CLI11 adds a second by default).
  app.failure_message([](const CLI::App*, const CLI::Error& e) {
    return "rastercheck: error: " + oneLineMessage(e.what()) + " (see --help)\n";
  });
  // Resource limits (fixtures/resource_estimate.h), accepted before or after the command
  // name; passed on through the environment, so that the renders `run` starts obey them.
  app.fallthrough();
  std::string max_memory;
  std::string max_work;
  app.add_option("--max-memory", max_memory,
                 "Refuse a render estimated to need more memory (e.g. 4G; default: the memory "
                 "available when it starts)");
  app.add_option("--max-work", max_work,
                 "Refuse a render estimated to need more operations (default 1e10, a few "
                 "minutes of the reference)");

  RenderArgs render;
  CLI::App* render_cmd = app.add_subcommand("render", "Render one fixture with one backend");
  render_cmd->add_option("scene", render.scene, "Fixture file (JSON)")->required();
  render_cmd
      ->add_option(
          "--backend,-b", render.backend,
          "ref, ref:painter, ref:abuffer, ref:subpixel=N, gl, gl:egl[:llvmpipe|:softpipe|:zink], "
          "gl:osmesa[:llvmpipe|:softpipe], gl:egl-device[:N]")
      ->capture_default_str();
  render_cmd->add_option("--out,-o", render.out, "Output folder (frame.exr, color.png, frame.json)")
      ->required();
  render_cmd->add_flag("--all-passes", render.all_passes,
                       "Multi-pass fixtures: also write what each pass before the frame pass drew "
                       "into its target, as OUT/passes/K-TARGET/ (a frame folder each)");

  ListArgs list;
  CLI::App* list_cmd = app.add_subcommand("list", "List fixtures: name, tags, description");
  list_cmd->add_option("paths", list.paths, "Fixture files or folders (default: the catalog)");
  list_cmd->add_flag("--json", list.json, "Print JSON");
  list_cmd->add_flag("--markdown", list.markdown, "Print a Markdown table");

  GenerateArgs generate;
  CLI::App* generate_cmd =
      app.add_subcommand("generate", "Write reproducible random fixtures (docs/random-scenes.md)");
  generate_cmd->add_option("--seed,-s", generate.seed, "Seed (0 to 2^64 - 1)")
      ->required()
      ->type_name("UINT");
  generate_cmd->add_option("--count,-n", generate.count, "Number of fixtures")
      ->capture_default_str();
  generate_cmd
      ->add_option("--first", generate.first,
                   "Index of the first fixture (scene i is the same whatever the count)")
      ->capture_default_str();
  generate_cmd->add_option("--out,-o", generate.out, "Output folder (replaced whole if generated)")
      ->required();
  generate_cmd->add_option("--max-size", generate.max_size, "Largest image, WxH")
      ->capture_default_str();
  generate_cmd
      ->add_option("--profile", generate.profile,
                   "Feature mix: all, generators, soups, meshes, textures, blend")
      ->capture_default_str();
  generate_cmd->add_option(
      "--meshes", generate.meshes,
      "Folder of assimp-testmodels' models (default /usr/share/assimp/models)");

  CompareArgs compare;
  CLI::App* compare_cmd =
      app.add_subcommand("compare", "Compare two frame folders written by `render`");
  compare_cmd->add_option("expected", compare.expected, "Expected frame folder")->required();
  compare_cmd->add_option("actual", compare.actual, "Actual frame folder")->required();
  compare_cmd->add_option("--out,-o", compare.out, "Report folder")->required();
  compare_cmd->add_option("--uncertainty", compare.uncertainty,
                          "Reference frame folder whose edge_dist/depth_gap classify the pair "
                          "(default: whichever side has them)");
  compare_cmd->add_option("--tolerance,-t", compare.tolerance,
                          "Override a threshold: CLASS.KEY=VALUE (visibility|depth|shading . "
                          "warn|fail, depth.slope_factor); repeatable");
  compare_cmd->add_flag("--diff-exr", compare.diff_exr,
                        "Write diff.exr also when the pair passes (by default only when not)");
  compare_cmd->add_flag("--flip", compare.flip,
                        "Also compute the LDR-FLIP perceptual error (report.json flip, "
                        "flip_heat.png); off by default: it costs more than the comparison");
  compare_cmd->add_option("--flip-threshold", compare.flip_threshold,
                          "Fail the pair when its mean LDR-FLIP error (0..1) exceeds this "
                          "(implies --flip)");

  RunArgs run;
  CLI::App* run_cmd = app.add_subcommand(
      "run", "Render fixtures with several backends and compare each with --against");
  run_cmd->add_option("inputs", run.inputs, "Fixture files or folders (default: the catalog)");
  run_cmd->add_option("--backends,-b", run.backends, "Backend SPECs, comma separated")
      ->required()
      ->delimiter(',');
  run_cmd->add_option("--against,-a", run.against, "SPEC every backend is compared with")
      ->capture_default_str();
  run_cmd->add_option("--out,-o", run.out, "Report folder")->required();
  run_cmd->add_option("--tolerance,-t", run.tolerance, "As for compare; repeatable");
  run_cmd->add_flag("--flip", run.flip, "As for compare: also compute LDR-FLIP for every pair");
  run_cmd->add_option("--flip-threshold", run.flip_threshold,
                      "Fail a pair whose mean LDR-FLIP error (0..1) exceeds this (implies --flip)");
  run_cmd->add_option("--jobs,-j", run.jobs, "Renders at a time (default: one per core)");
  run_cmd->add_option("--expectations", run.expectations,
                      "Known driver differences to mark as known failures: a file, or 'none' "
                      "(default: fixtures/expectations.json)");
  run_cmd
      ->add_option("--timeout", run.timeout_seconds,
                   "Seconds one render may take before its worker is killed and the pair is an "
                   "error row (0: no watchdog)")
      ->capture_default_str();
  run_cmd->add_flag("--keep-frames", run.keep_frames,
                    "Write frames and pair images of passing pairs too (by default only of "
                    "pairs that warn, fail or error)");
  run_cmd->add_option("--shard", run.shard,
                      "Run part K of N (K/N, 1-based) of the whole run, or `env`: from "
                      "RASTERCHECK_SHARD, CI_NODE_INDEX/CI_NODE_TOTAL or "
                      "JOB_COMPLETION_INDEX/JOB_COMPLETIONS; join the parts with `merge`");
  run_cmd->add_option("--retries", run.retries,
                      "Render every failing or erroring GL pair N more times, each in a fresh "
                      "worker: renders that disagree make the pair a flake (default 1; 0: "
                      "never)");
  run_cmd->add_option("--baseline", run.baseline,
                      "deqp-runner baseline (name,Status lines, e.g. a fails.txt or an earlier "
                      "results.csv): failures it lists are expected; the exit code says whether "
                      "the run matches it");
  run_cmd->add_option("--flakes", run.flakes,
                      "deqp-runner flakes file: regular expressions; a failing test one matches "
                      "is a KnownFlake");
  run_cmd->add_option("--skips", run.skips,
                      "deqp-runner skips file: regular expressions; tests one matches are not "
                      "rendered (Skip)");
  run_cmd->add_option("--caselist", run.caselist,
                      "Fixture names, one per line: run these, in this order (deqp-runner "
                      "caselist)");
  run_cmd
      ->add_option("--fraction", run.fraction,
                   "Run every Nth fixture of the list (deqp-runner --fraction)")
      ->check(CLI::PositiveNumber);
  run_cmd
      ->add_option("--fraction-start", run.fraction_start,
                   "Start --fraction at the Mth fixture, 1-based (deqp-runner "
                   "--fraction-start)")
      ->check(CLI::PositiveNumber);
  run_cmd->add_flag("!--no-variants", run.variants,
                    "Skip the variant probes (subpixel precision, tie-break, depth rounding) "
                    "of each GL backend");

  ExplainArgs explain;
  CLI::App* explain_cmd = app.add_subcommand(
      "explain", "Tell the reference's history of one pixel and what each backend has there");
  explain_cmd->add_option("scene", explain.scene, "Fixture file (JSON)")->required();
  explain_cmd->add_option("--pixel,-p", explain.pixel, "X,Y in image coordinates (origin top-left)")
      ->required();
  explain_cmd->add_option("--backends,-b", explain.backends, "Backend SPECs to compare there")
      ->delimiter(',');
  explain_cmd
      ->add_option(
          "--reference", explain.reference,
          "Reference SPEC whose history is told (ref, ref:painter, ref:abuffer, ref:subpixel=N)")
      ->capture_default_str();
  explain_cmd->add_option("--tolerance,-t", explain.tolerance, "As for compare; repeatable");
  explain_cmd->add_flag("--json", explain.json, "Print JSON (documented in docs/explain.md)");

  ReduceArgs reduce;
  CLI::App* reduce_cmd = app.add_subcommand(
      "reduce", "Delta-debug a failing fixture down to a minimal one that still fails");
  reduce_cmd->add_option("scene", reduce.scene, "Fixture file (JSON)")->required();
  reduce_cmd->add_option("--expected", reduce.expected, "Expected backend SPEC")->required();
  reduce_cmd->add_option("--actual", reduce.actual, "Actual backend SPEC")->required();
  reduce_cmd->add_option("--out,-o", reduce.out, "Where to write the minimal fixture (JSON)")
      ->required();
  reduce_cmd
      ->add_option("--class", reduce.failure_class,
                   "Class that must keep failing (default: the one that fails first of "
                   "visibility, depth, shading)")
      ->check(CLI::IsMember({"visibility", "depth", "shading"}));
  reduce_cmd
      ->add_option("--timeout", reduce.timeout_seconds,
                   "Stop after this many seconds and write the smallest failing scene so far")
      ->capture_default_str();
  reduce_cmd->add_option("--tolerance,-t", reduce.tolerance, "As for compare; repeatable");

  CampaignArgs campaign;
  CLI::App* campaign_cmd = app.add_subcommand(
      "campaign",
      "Generate random scenes, run them on backends, reduce and group every failure "
      "(docs/campaigns.md); --mutations: measure how often injected GL faults are caught");
  campaign_cmd->add_option("--seed,-s", campaign.seed, "Seed of the random scenes (0 to 2^64 - 1)")
      ->required()
      ->type_name("UINT");
  campaign_cmd->add_option("--count,-n", campaign.count, "Number of scenes")->capture_default_str();
  campaign_cmd->add_option("--backends,-b", campaign.backends, "Backend SPECs, comma separated")
      ->required()
      ->delimiter(',');
  campaign_cmd->add_option("--against,-a", campaign.against, "SPEC every backend is compared with")
      ->capture_default_str();
  campaign_cmd
      ->add_option("--out,-o", campaign.out,
                   "Campaign folder (the same command on the same folder continues it)")
      ->required();
  campaign_cmd
      ->add_option("--reduce-seconds", campaign.reduce_seconds,
                   "Time limit of each failure's reduction (0: do not reduce)")
      ->capture_default_str();
  campaign_cmd->add_option("--jobs,-j", campaign.jobs,
                           "Children at a time (default: one per core)");
  campaign_cmd->add_option("--batch", campaign.batch, "Scenes per `run` child")
      ->capture_default_str();
  campaign_cmd->add_option("--expectations", campaign.expectations,
                           "Known driver differences, as for run: a group every failure of "
                           "which one covers is reported as known and does not fail the "
                           "campaign (default: fixtures/expectations.json)");
  campaign_cmd->add_option("--profile", campaign.profile, "Feature mix, as for generate")
      ->capture_default_str();
  campaign_cmd->add_option("--max-size", campaign.max_size, "Largest image, WxH")
      ->capture_default_str();
  campaign_cmd->add_option("--meshes", campaign.meshes, "Folder of assimp-testmodels' models");
  campaign_cmd->add_option("--tolerance,-t", campaign.tolerance, "As for compare; repeatable");
  campaign_cmd->add_flag("--mutations", campaign.mutations,
                         "The mutation study: inject each GL fault into every scene and report "
                         "how often it is caught in its class");
  campaign_cmd
      ->add_option("--faults", campaign.faults,
                   "--mutations: faults to inject, comma separated (default: every fault of "
                   "docs/campaigns.md)")
      ->delimiter(',');

  AccuracyArgs accuracy;
  CLI::App* accuracy_cmd = app.add_subcommand(
      "accuracy", "Write the accuracy report (Markdown) from the report.json of run folders");
  accuracy_cmd->add_option("runs", accuracy.runs, "Folders written by `run`")->required();
  accuracy_cmd->add_option("--out,-o", accuracy.out, "Markdown file (default: stdout)");
  accuracy_cmd->add_option("--catalog", accuracy.catalogs,
                           "Fixture folders to find tags by name (default: the catalog)");
  accuracy_cmd->add_option("--expectations", accuracy.expectations,
                           "Known differences to list (fixtures/expectations.json)");
  accuracy_cmd->add_option("--command", accuracy.command,
                           "How the document says it was made (Markdown)");

  MergeArgs merge;
  CLI::App* merge_cmd =
      app.add_subcommand("merge", "Join the folders of `run --shard K/N` into one run's report");
  merge_cmd->add_option("runs", merge.runs, "Folders written by `run --shard`")->required();
  merge_cmd->add_option("--out,-o", merge.out, "Report folder")->required();
  merge_cmd->add_option("--baseline", merge.baseline, "As for run, applied to the merged run");
  merge_cmd->add_option("--flakes", merge.flakes, "As for run");
  merge_cmd->add_option("--skips", merge.skips,
                        "As for run (the parts have skipped already; names the file in the "
                        "report)");

  DiffRunsArgs diff_runs;
  CLI::App* diff_runs_cmd = app.add_subcommand(
      "diff-runs", "Regressions, fixes, new and vanished pairs between two run folders");
  diff_runs_cmd->add_option("old", diff_runs.old_run, "The earlier run folder")->required();
  diff_runs_cmd->add_option("new", diff_runs.new_run, "The later run folder")->required();
  diff_runs_cmd->add_flag("--json", diff_runs.json, "Print JSON instead of text");
  diff_runs_cmd->add_option("--out,-o", diff_runs.out,
                            "Also write diff.txt, diff.json and diff.html into this folder");

  // `run`'s workers (app/worker.h); not for people, so not in --help.
  std::string worker_spec;
  CLI::App* worker_cmd = app.add_subcommand("worker", "");
  worker_cmd->group("");
  worker_cmd->add_option("--backend", worker_spec)->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help/version or the one-line parse error
    return code == 0 ? kExitPass : kExitInput;
  }

  try {
    if (!max_memory.empty()) {
      parseByteSize(max_memory, "--max-memory");
      ::setenv("RASTERCHECK_MAX_MEMORY", max_memory.c_str(), 1);
    }
    if (!max_work.empty()) {
      parseWork(max_work, "--max-work");
      ::setenv("RASTERCHECK_MAX_WORK", max_work.c_str(), 1);
    }
    if (*render_cmd) return renderCommand(render);
    if (*list_cmd) return listCommand(list);
    if (*generate_cmd) return generateCommand(generate);
    if (*compare_cmd) return compareCommand(compare);
    if (*run_cmd) return runCommand(run);
    if (*accuracy_cmd) return accuracyCommand(accuracy);
    if (*explain_cmd) return explainCommand(explain);
    if (*reduce_cmd) return reduceCommand(reduce);
    if (*campaign_cmd) {
      campaign.command_line = "rastercheck";
      for (int i = 1; i < argc; ++i) campaign.command_line += " " + shellQuote(argv[i]);
      return campaignCommand(campaign);
    }
    if (*merge_cmd) return mergeCommand(merge);
    if (*diff_runs_cmd) return diffRunsCommand(diff_runs);
    if (*worker_cmd) return workerCommand(worker_spec);
  } catch (const InputError& e) {
    std::cerr << "rastercheck: error: " << oneLineMessage(e.what()) << '\n';
    return kExitInput;
  } catch (const NotSupportedError& e) {
    std::cerr << "rastercheck: " << e.what() << '\n';  // "not supported: ..."
    return kExitBackend;
  } catch (const BackendError& e) {
    std::cerr << "rastercheck: backend error: " << oneLineMessage(e.what()) << '\n';
    return kExitBackend;
  } catch (const std::exception& e) {
    std::cerr << "rastercheck: internal error: " << oneLineMessage(e.what()) << '\n';
    return kExitBackend;
  }
  return kExitInput;
}

}  // namespace rc
