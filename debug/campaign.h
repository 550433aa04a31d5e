// A campaign's bookkeeping (docs/campaigns.md): the failures found in the report.json of
// its runs, their signatures (backend, class, and what the state probes showed the failure
// needs), the groups they form, and the summary written from them (summary.md,
// summary.json, index.html). No rendering, no processes: `rastercheck campaign` (app/)
// runs `run`, `reduce` and the probes as child processes and feeds the results here.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/expectations.h"

namespace rc {

inline constexpr const char* kCampaignFormat = "rastercheck-campaign/1";

// One failing class of one pair (a pair that fails in two classes is two failures), or a
// pair that could not be compared (class "error").
struct CampaignFailure {
  std::string id;            // unique, a folder name: "<fixture>__<backend>__<class>"
  std::string fixture;       // fixture name
  std::string fixture_file;  // absolute path of the fixture the run read
  std::vector<std::string> tags;
  std::string expected;  // SPECs
  std::string actual;
  std::string cls;      // visibility, depth, shading or error
  std::string kind;     // visibility: missing, extra or wrong_primitive (most hard pixels)
  std::string message;  // the report row's one-line description (error: the error)
  std::string run;      // the run folder holding the row, relative to the campaign folder
  // The expectations entry (fixtures/expectations.json id) that covers this class of the
  // row, as the run marked it ("known" in report.json); empty when none does.
  std::string known;
  std::string images;  // the pair's image folder, relative to the campaign folder
  // Reduction (`rastercheck reduce`): "reduced", "timed_out" (smallest failing scene
  // found in the time), "failed" (reduce could not run or did not reproduce), "skipped"
  // (errors are not reduced), or empty while pending.
  std::string reduction;
  std::string reduced_file;              // relative to the campaign folder; empty unless reduced
  std::string reduce_note;               // reduce's closing lines, or why it failed
  std::uint64_t triangles = 0;           // of the reduced fixture (0: unknown)
  std::optional<bool> reproduces;        // the reduced fixture still fails in the class
  std::vector<std::string> involved;     // from the probes (debug/probes.h), sorted
  std::vector<std::string> probe_notes;  // probes that could not be compared, and why
};

nlohmann::json toJson(const CampaignFailure& failure);
// Throws InputError naming `source` and the key when a field is missing or mistyped.
CampaignFailure campaignFailureFromJson(const nlohmann::json& j, const std::string& source);

// The failures of one run's report.json (`run_rel`: the run folder relative to the
// campaign folder; `fixture_file(name)` gives a fixture's file and tags). Rows that pass
// or warn give none. CampaignFailure::known: with `expectations`, what they say of the
// row now (an entry added after the run counts; one removed no longer does), else what
// the run marked. Throws InputError for a malformed report.
struct FixtureInfo {
  std::string file;
  std::vector<std::string> tags;
};
std::vector<CampaignFailure> failuresOfReport(
    const nlohmann::json& report, const std::string& run_rel,
    const std::function<FixtureInfo(const std::string& fixture)>& fixture_info,
    const std::string& source, const Expectations* expectations = nullptr);

// The signature that groups failures: actual backend (and the expected SPEC when it is not
// `ref`), class (visibility with its kind), and what the probes found involved; "not
// reproduced" when the reduced fixture did not fail again; for errors, the message with
// the fixture's own name taken out.
std::string signatureOf(const CampaignFailure& failure);

struct CampaignGroup {
  std::string id;  // 8 hex digits of the signature's FNV-1a hash: stable between runs
  std::string signature;
  std::string expected;
  std::string actual;
  std::string cls;
  std::string kind;
  std::vector<std::string> involved;
  std::vector<const CampaignFailure*> failures;  // by fixture name
  // The smallest reduced fixture that still fails (fewest triangles), else the smallest
  // reduced one, else none.
  const CampaignFailure* reproducer = nullptr;
  std::vector<std::string> common_tags;  // tags every failing fixture of the group has
};

// Groups by signature, largest group first (then by signature).
std::vector<CampaignGroup> groupFailures(const std::vector<CampaignFailure>& failures);

// The command that reproduces a group: `rastercheck run REPRODUCER --backends ACTUAL
// --against EXPECTED --out OUT` with the campaign's tolerance options, shell-quoted.
std::string reproduceCommand(const std::filesystem::path& reproducer, const std::string& expected,
                             const std::string& actual,
                             const std::vector<std::string>& tolerance_args,
                             const std::filesystem::path& out);

// Whether a known-differences entry (fixtures/expectations.json, compare/expectations.h)
// covers a group: `checked` false only for summaries written before expectations were
// checked ("not checked").
struct ExpectationVerdict {
  bool checked = false;
  std::string entry;  // the covering entry, for people; empty when none covers the group
};
using ExpectationLookup = std::function<ExpectationVerdict(const CampaignGroup&)>;

// Pass/warn/fail/error pairs of one backend over the campaign's runs.
struct BackendCounts {
  std::uint64_t pass = 0;
  std::uint64_t warn = 0;
  std::uint64_t fail = 0;
  std::uint64_t error = 0;
  std::uint64_t flake = 0;  // renders that disagreed when `run` retried them (docs/ci.md)
  std::uint64_t total() const { return pass + warn + fail + error + flake; }
};
// Adds the rows of one report.json, keyed "ACTUAL" (or "ACTUAL vs EXPECTED" when the
// expected SPEC is not ref).
void countReport(const nlohmann::json& report, std::map<std::string, BackendCounts>& counts);

struct CampaignSummary {
  nlohmann::json options = nlohmann::json::object();  // as campaign.json holds them
  std::string command;  // the command line that (re)started the campaign
  std::uint64_t scenes_total = 0;
  std::uint64_t scenes_run = 0;
  std::uint64_t failures_done = 0;  // reduced and probed (or skipped)
  bool complete = false;
  std::vector<std::string> runs;  // run folders, relative
  std::map<std::string, BackendCounts> backends;
  std::vector<CampaignFailure> failures;
  nlohmann::json variants = nlohmann::json::object();  // the first run's, when probed
  // Per group id: the reproducer file (relative to the campaign folder) and its command.
  struct GroupFiles {
    std::string reproducer;
    std::string command;
    ExpectationVerdict expectation;
  };
  std::map<std::string, GroupFiles> group_files;
};

// The three summary files' contents. `groups` come from groupFailures(summary.failures).
std::string summaryMarkdown(const CampaignSummary& summary,
                            const std::vector<CampaignGroup>& groups);
nlohmann::json summaryJson(const CampaignSummary& summary,
                           const std::vector<CampaignGroup>& groups);
std::string indexHtml(const CampaignSummary& summary, const std::vector<CampaignGroup>& groups);

// Exit status of a campaign: 3 when a pair could not run, else 1 when a group is not
// covered by an expectation (any failing group, while expectations are not checked),
// else 0.
int campaignExitCode(const CampaignSummary& summary, const std::vector<CampaignGroup>& groups);

// A string as one shell word ('...' when it needs quoting).
std::string shellQuote(const std::string& word);

// What is known mid-campaign, for the time left.
struct CampaignProgress {
  std::uint64_t scenes_left = 0;
  std::uint64_t scenes_done = 0;     // in this process (the measured ones)
  double scene_seconds = 0.0;        // wall time those took
  std::uint64_t failures_found = 0;  // in the scenes done, all processes
  std::uint64_t scenes_done_total = 0;
  std::uint64_t failures_left = 0;   // found and not yet reduced and probed
  std::uint64_t failures_done = 0;   // in this process
  double failure_seconds = 0.0;      // wall time those took
  double reduce_cap_seconds = 60.0;  // --reduce-seconds
  int parallel = 1;                  // reductions at a time
};
// Seconds left: scenes at the measured rate, then the failures found so far and those the
// scenes left will likely add (at the failure rate seen so far), at the measured time per
// failure (before any was measured: half the reduce cap per failure, shared by the
// parallel reductions). Empty while scenes are left and none was measured.
std::optional<double> secondsLeft(const CampaignProgress& p);

}  // namespace rc
