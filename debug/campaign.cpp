// A campaign's failures, signatures, groups and summary: see campaign.h.
#include "debug/campaign.h"

#include <algorithm>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "compare/report_text.h"
#include "fixtures/errors.h"

namespace rc {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kClasses[] = {"visibility", "depth", "shading"};

// Reads one report row or failure record; every error names the source and key.
class Fields {
 public:
  Fields(const json& j, std::string where) : j_(j), where_(std::move(where)) {
    if (!j_.is_object()) fail("", "must be an object");
  }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError(fmt::format("{}{}{}: {}", where_, key.empty() ? "" : ".", key, what));
  }
  std::string text(const char* key, bool required = true) const {
    if (!j_.contains(key) || j_[key].is_null()) {
      if (required) fail(key, "missing");
      return {};
    }
    if (!j_[key].is_string()) fail(key, "must be a string");
    return j_[key].get<std::string>();
  }
  std::vector<std::string> texts(const char* key) const {
    std::vector<std::string> out;
    if (!j_.contains(key)) return out;
    if (!j_[key].is_array()) fail(key, "must be an array of strings");
    for (const json& v : j_[key]) {
      if (!v.is_string()) fail(key, "must be an array of strings");
      out.push_back(v.get<std::string>());
    }
    return out;
  }
  double number(const json& obj, const char* key) const {
    return obj.is_object() && obj.contains(key) && obj[key].is_number() ? obj[key].get<double>()
                                                                        : 0.0;
  }

 private:
  const json& j_;
  std::string where_;
};

std::string slug(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) || c == '-' ? c : '_';
  return out;
}

std::string pixelText(const json& v) {
  return v.is_array() && v.size() == 2 ? fmt::format("({},{})", v[0].dump(), v[1].dump())
                                       : std::string("(none)");
}

// One line on the failing class of a report row, from its numbers.
std::string classMessage(const json& row, const std::string& cls) {
  const json& c = row[cls];
  auto n = [&](const char* key) {
    if (!c.contains(key) || c[key].is_null()) return std::string("?");
    return c[key].is_number() ? fmt::format("{:.4g}", c[key].get<double>()) : c[key].dump();
  };
  if (cls == "visibility")
    return fmt::format("{} hard px (missing {}, extra {}, wrong_primitive {}), worst {}", n("hard"),
                       n("missing_hard"), n("extra_hard"), n("wrong_primitive_hard"),
                       pixelText(c.value("worst", json())));
  if (cls == "depth")
    return fmt::format("{} px over tolerance, max {} steps, worst {}: {} steps, allowance {}",
                       n("over_tolerance"), n("max_steps"), pixelText(c.value("worst", json())),
                       n("worst_steps"), n("worst_allowance"));
  return fmt::format("{} px over tolerance, max {} units, worst {}: {} units, allowance {}",
                     n("over_tolerance"), n("max_abs"), pixelText(c.value("worst", json())),
                     n("worst_abs"), n("worst_allowance"));
}

// The visibility kind with the most hard pixels (first of missing, extra, wrong on ties).
std::string visibilityKind(const json& v) {
  std::string kind = "missing";
  double most = -1.0;
  for (const char* k : {"missing", "extra", "wrong_primitive"}) {
    const std::string key = std::string(k) + "_hard";
    const double count = v.contains(key) && v[key].is_number() ? v[key].get<double>() : 0.0;
    if (count > most) {
      most = count;
      kind = k;
    }
  }
  return kind;
}

std::uint32_t fnv1a(const std::string& s) {
  std::uint32_t h = 2166136261u;
  for (unsigned char c : s) {
    h ^= c;
    h *= 16777619u;
  }
  return h;
}

// Markdown table cells: no '|' or newline inside.
std::string cell(const std::string& s) {
  std::string out;
  for (char c : s)
    out += c == '|' ? std::string("\\|") : c == '\n' ? std::string(" ") : std::string(1, c);
  return out;
}

std::string involvedText(const std::vector<std::string>& involved) {
  return involved.empty() ? std::string("independent of the probed state")
                          : fmt::format("{}", fmt::join(involved, ", "));
}

std::string expectationText(const ExpectationVerdict& e) {
  if (!e.checked) return "not checked";
  return e.entry.empty() ? "no" : "yes: " + e.entry;
}

}  // namespace

// ---- failures ----

json toJson(const CampaignFailure& f) {
  json j = {{"id", f.id},
            {"fixture", f.fixture},
            {"fixture_file", f.fixture_file},
            {"tags", f.tags},
            {"expected", f.expected},
            {"actual", f.actual},
            {"class", f.cls},
            {"kind", f.kind},
            {"message", f.message},
            {"run", f.run},
            {"known", f.known},
            {"images", f.images},
            {"reduction", f.reduction},
            {"reduced_file", f.reduced_file},
            {"reduce_note", f.reduce_note},
            {"triangles", f.triangles},
            {"involved", f.involved},
            {"probe_notes", f.probe_notes}};
  j["reproduces"] = f.reproduces ? json(*f.reproduces) : json(nullptr);
  return j;
}

CampaignFailure campaignFailureFromJson(const json& j, const std::string& source) {
  const Fields r(j, source);
  CampaignFailure f;
  f.id = r.text("id");
  f.fixture = r.text("fixture");
  f.fixture_file = r.text("fixture_file", false);
  f.tags = r.texts("tags");
  f.expected = r.text("expected");
  f.actual = r.text("actual");
  f.cls = r.text("class");
  if (f.cls != "error" &&
      std::find(std::begin(kClasses), std::end(kClasses), f.cls) == std::end(kClasses))
    r.fail("class", fmt::format("\"{}\" is not visibility, depth, shading or error", f.cls));
  f.kind = r.text("kind", false);
  f.message = r.text("message", false);
  f.run = r.text("run", false);
  f.images = r.text("images", false);
  f.known = r.text("known", false);
  f.reduction = r.text("reduction", false);
  f.reduced_file = r.text("reduced_file", false);
  f.reduce_note = r.text("reduce_note", false);
  if (j.contains("triangles")) {
    if (!j["triangles"].is_number_unsigned()) r.fail("triangles", "must be a count");
    f.triangles = j["triangles"].get<std::uint64_t>();
  }
  if (j.contains("reproduces") && !j["reproduces"].is_null()) {
    if (!j["reproduces"].is_boolean()) r.fail("reproduces", "must be true, false or null");
    f.reproduces = j["reproduces"].get<bool>();
  }
  f.involved = r.texts("involved");
  f.probe_notes = r.texts("probe_notes");
  return f;
}

std::vector<CampaignFailure> failuresOfReport(
    const json& report, const std::string& run_rel,
    const std::function<FixtureInfo(const std::string&)>& fixture_info, const std::string& source,
    const Expectations* expectations) {
  if (!report.is_object() || !report.contains("results") || !report["results"].is_array())
    throw InputError(fmt::format("{}: results: missing or not an array", source));
  std::vector<CampaignFailure> out;
  for (std::size_t i = 0; i < report["results"].size(); ++i) {
    const json& row = report["results"][i];
    const Fields r(row, fmt::format("{}: results[{}]", source, i));
    const std::string status = r.text("status");
    if (status != "fail" && status != "error") continue;
    CampaignFailure base;
    base.fixture = r.text("fixture");
    base.expected = r.text("expected");
    base.actual = r.text("actual");
    const FixtureInfo info = fixture_info(base.fixture);
    base.fixture_file = info.file;
    base.tags = info.tags;
    base.run = run_rel;
    if (row.contains("images") && row["images"].is_object()) {
      for (const auto& [kind, file] : row["images"].items()) {
        if (!file.is_string()) continue;
        base.images = (fs::path(run_rel) / fs::path(file.get<std::string>()).parent_path())
                          .lexically_normal()
                          .generic_string();
        break;
      }
    }
    // What the expectations say of the row now, from the same facts `run` matched them
    // against: fixture, its tags, actual backend, its GL version, the render state and the
    // failing classes.
    std::vector<KnownFailure> known_now;
    if (expectations && status == "fail") {
      PairResult pair;
      pair.fixture = base.fixture;
      pair.actual = base.actual;
      pair.status = Status::Fail;
      pair.tags = base.tags;  // entries scoped by tags match the fixture's, as in `run`
      if (row.contains("state") && row["state"].is_object()) pair.state = row["state"];
      const json* stack =
          row.contains("stacks") && row["stacks"].is_object() && row["stacks"].contains("actual")
              ? &row["stacks"]["actual"]
              : nullptr;
      if (stack && stack->is_object() && stack->contains("gl_version") &&
          (*stack)["gl_version"].is_string())
        pair.actual_driver = (*stack)["gl_version"].get<std::string>();
      for (auto [cls, status_of] :
           {std::pair{"visibility", &pair.visibility.status},
            std::pair{"depth", &pair.depth.status}, std::pair{"shading", &pair.shading.status}}) {
        const bool failed =
            row.contains(cls) && row[cls].is_object() && row[cls].value("status", "") == "fail";
        *status_of = failed ? Status::Fail : Status::Pass;
      }
      known_now = knownFailuresOf(*expectations, pair);
    }
    auto add = [&](const std::string& cls) {
      CampaignFailure f = base;
      f.cls = cls;
      f.id = fmt::format("{}__{}__{}", slug(f.fixture), slug(f.actual), cls);
      if (f.expected != "ref") f.id += "__vs_" + slug(f.expected);
      if (cls == "error") {
        f.message = r.text("error", false);
        f.reduction = "skipped";
      } else {
        f.message = classMessage(row, cls);
        if (cls == "visibility") f.kind = visibilityKind(row[cls]);
        if (expectations) {
          for (const KnownFailure& k : known_now)
            if (k.cls == cls) f.known = k.id;
        } else if (row.contains("known") && row["known"].is_array()) {
          for (const json& k : row["known"])
            if (k.is_object() && k.value("class", "") == cls) f.known = k.value("id", "");
        }
      }
      out.push_back(std::move(f));
    };
    if (status == "error") {
      add("error");
      continue;
    }
    for (const char* cls : kClasses) {
      if (row.contains(cls) && row[cls].is_object() && row[cls].value("status", "") == "fail")
        add(cls);
    }
  }
  return out;
}

// ---- signatures and groups ----

std::string signatureOf(const CampaignFailure& f) {
  std::string s = f.actual;
  if (f.expected != "ref") s += " vs " + f.expected;
  s += " | " + f.cls;
  if (!f.kind.empty()) s += ":" + f.kind;
  if (f.cls == "error") {
    // The same error on another fixture is the same group: take the fixture name out.
    std::string message = f.message;
    for (std::size_t at; !f.fixture.empty() && (at = message.find(f.fixture)) != std::string::npos;)
      message.replace(at, f.fixture.size(), "FIXTURE");
    return s + " | " + message;
  }
  if (f.reproduces == false) return s + " | not reproduced by its reduced fixture";
  return s + " | " + involvedText(f.involved);
}

std::vector<CampaignGroup> groupFailures(const std::vector<CampaignFailure>& failures) {
  std::map<std::string, CampaignGroup> by_signature;
  for (const CampaignFailure& f : failures) {
    const std::string sig = signatureOf(f);
    CampaignGroup& g = by_signature[sig];
    if (g.failures.empty()) {
      g.signature = sig;
      g.id = fmt::format("{:08x}", fnv1a(sig));
      g.expected = f.expected;
      g.actual = f.actual;
      g.cls = f.cls;
      g.kind = f.kind;
      g.involved = f.involved;
    }
    g.failures.push_back(&f);
  }
  std::vector<CampaignGroup> groups;
  for (auto& [sig, g] : by_signature) {
    std::sort(g.failures.begin(), g.failures.end(),
              [](const CampaignFailure* a, const CampaignFailure* b) {
                return a->fixture != b->fixture ? a->fixture < b->fixture : a->id < b->id;
              });
    auto better = [](const CampaignFailure* a, const CampaignFailure* b) {
      // Reproduces beats not; then fewer triangles; then the first by fixture.
      if (a->reproduces.value_or(false) != b->reproduces.value_or(false))
        return a->reproduces.value_or(false);
      return a->triangles < b->triangles;
    };
    for (const CampaignFailure* f : g.failures)
      if (!f->reduced_file.empty() && (!g.reproducer || better(f, g.reproducer))) g.reproducer = f;
    std::set<std::string> common(g.failures.front()->tags.begin(), g.failures.front()->tags.end());
    for (const CampaignFailure* f : g.failures) {
      const std::set<std::string> tags(f->tags.begin(), f->tags.end());
      std::erase_if(common, [&](const std::string& t) { return !tags.contains(t); });
    }
    common.erase("random");  // every generated fixture has it
    g.common_tags.assign(common.begin(), common.end());
    groups.push_back(std::move(g));
  }
  std::sort(groups.begin(), groups.end(), [](const CampaignGroup& a, const CampaignGroup& b) {
    return a.failures.size() != b.failures.size() ? a.failures.size() > b.failures.size()
                                                  : a.signature < b.signature;
  });
  return groups;
}

std::string shellQuote(const std::string& word) {
  const bool plain = !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) ||
           std::string_view("/._-:=,+@%").find(c) != std::string_view::npos;
  });
  if (plain) return word;
  std::string out = "'";
  for (char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string reproduceCommand(const fs::path& reproducer, const std::string& expected,
                             const std::string& actual,
                             const std::vector<std::string>& tolerance_args, const fs::path& out) {
  std::string cmd =
      fmt::format("rastercheck run {} --backends {} --against {}", shellQuote(reproducer.string()),
                  shellQuote(actual), shellQuote(expected));
  for (const std::string& t : tolerance_args) cmd += " -t " + shellQuote(t);
  return cmd + " --out " + shellQuote(out.string());
}

// ---- counts ----

void countReport(const json& report, std::map<std::string, BackendCounts>& counts) {
  if (!report.contains("results") || !report["results"].is_array()) return;
  for (const json& row : report["results"]) {
    if (!row.is_object()) continue;
    std::string key = row.value("actual", std::string("?"));
    const std::string expected = row.value("expected", std::string("ref"));
    if (expected != "ref") key += " vs " + expected;
    BackendCounts& c = counts[key];
    const std::string status = row.value("status", std::string());
    if (status == "pass") ++c.pass;
    if (status == "warn") ++c.warn;
    if (status == "fail") ++c.fail;
    if (status == "error") ++c.error;
    if (status == "flake") ++c.flake;
  }
}

int campaignExitCode(const CampaignSummary& summary, const std::vector<CampaignGroup>& groups) {
  for (const auto& [backend, c] : summary.backends)
    if (c.error > 0) return kExitBackend;
  for (const CampaignGroup& g : groups) {
    const auto it = summary.group_files.find(g.id);
    const bool covered = it != summary.group_files.end() && it->second.expectation.checked &&
                         !it->second.expectation.entry.empty();
    if (!covered) return kExitFail;
  }
  return kExitPass;
}

std::optional<double> secondsLeft(const CampaignProgress& p) {
  if (p.scenes_left > 0 && p.scenes_done == 0) return std::nullopt;
  const double per_scene =
      p.scenes_done > 0 ? p.scene_seconds / static_cast<double>(p.scenes_done) : 0.0;
  const double rate = p.scenes_done_total > 0 ? static_cast<double>(p.failures_found) /
                                                    static_cast<double>(p.scenes_done_total)
                                              : 0.0;
  const double failures =
      static_cast<double>(p.failures_left) + rate * static_cast<double>(p.scenes_left);
  const double per_failure =
      p.failures_done > 0
          ? p.failure_seconds / static_cast<double>(p.failures_done)
          : 0.5 * p.reduce_cap_seconds / static_cast<double>(std::max(1, p.parallel));
  return per_scene * static_cast<double>(p.scenes_left) + failures * per_failure;
}

// ---- the summary files ----

namespace {

const CampaignSummary::GroupFiles& filesOf(const CampaignSummary& s, const CampaignGroup& g) {
  static const CampaignSummary::GroupFiles none;
  const auto it = s.group_files.find(g.id);
  return it == s.group_files.end() ? none : it->second;
}

std::string reductionText(const CampaignFailure& f) {
  if (f.reduction.empty()) return "pending";
  if (f.reduction == "reduced" || f.reduction == "timed_out")
    return fmt::format("{}{} triangles{}", f.reduction == "timed_out" ? "time ran out at " : "",
                       f.triangles,
                       f.reproduces == false ? ", does NOT fail again"
                       : f.reproduces        ? ", fails again"
                                             : "");
  return f.reduction;
}

}  // namespace

std::string summaryMarkdown(const CampaignSummary& s, const std::vector<CampaignGroup>& groups) {
  std::string md = "# Campaign summary\n\n";
  const json& o = s.options;
  md += fmt::format("Command: `{}`\n\n", s.command);
  md += fmt::format(
      "{} of {} scenes run (seed {}, profile {}, largest image {}), {} of {} failures reduced and "
      "probed. {}\n\n",
      s.scenes_run, s.scenes_total, o.value("seed", json("?")).dump(),
      o.value("profile", std::string("all")), o.value("max_size", std::string("?")),
      s.failures_done, s.failures.size(),
      s.complete ? "The campaign is complete."
                 : "**Incomplete**: run the same command again to continue where it stopped.");
  md +=
      "## Pairs per backend\n\n| backend | pairs | pass | warn | fail | error | flake "
      "|\n|---|---|---|---|---|---|---|\n";
  for (const auto& [backend, c] : s.backends)
    md += fmt::format("| `{}` | {} | {} | {} | {} | {} | {} |\n", backend, c.total(), c.pass,
                      c.warn, c.fail, c.error, c.flake);
  md += "\n## Groups\n\n";
  if (groups.empty()) {
    md += "No failures.\n";
  } else {
    md += fmt::format(
        "{} failures in {} groups. A group is one signature: backend, class (visibility with the "
        "kind of most hard pixels) and what the probes of its reduced fixtures showed the "
        "failure needs (docs/campaigns.md).\n\n",
        s.failures.size(), groups.size());
    md +=
        "| group | backend | class | needs | failures | reproducer | known difference |\n"
        "|---|---|---|---|---|---|---|\n";
    for (const CampaignGroup& g : groups) {
      const auto& files = filesOf(s, g);
      md += fmt::format(
          "| [{}](#group-{}) | `{}` | {} | {} | {} | {} | {} |\n", g.id, g.id,
          g.expected == "ref" ? g.actual : g.actual + " vs " + g.expected,
          g.kind.empty() ? g.cls : g.cls + ":" + g.kind,
          cell(g.cls == "error" ? "-" : involvedText(g.involved)), g.failures.size(),
          files.reproducer.empty() ? "none" : fmt::format("[file]({})", files.reproducer),
          cell(expectationText(files.expectation)));
    }
    for (const CampaignGroup& g : groups) {
      const auto& files = filesOf(s, g);
      md += fmt::format("\n### Group {}\n\n<a id=\"group-{}\"></a>Signature: `{}`\n\n", g.id, g.id,
                        g.signature);
      md += fmt::format("- failures: {}\n", g.failures.size());
      if (!g.common_tags.empty())
        md += fmt::format("- tags every failing fixture has: {}\n", fmt::join(g.common_tags, ", "));
      if (!files.reproducer.empty()) {
        md += fmt::format("- reproducer: [{}]({}) ({})\n", files.reproducer, files.reproducer,
                          reductionText(*g.reproducer));
        md += fmt::format("- reproduce: `{}`\n", files.command);
      } else {
        md += "- reproducer: none (not reduced)\n";
      }
      md += fmt::format("- known difference: {}\n", expectationText(files.expectation));
      md += "- examples:\n";
      for (std::size_t i = 0; i < g.failures.size() && i < 5; ++i) {
        const CampaignFailure& f = *g.failures[i];
        md += fmt::format("  - `{}`: {} (reduction: {}; images: {})\n", f.fixture, f.message,
                          reductionText(f), f.images.empty() ? "none" : f.images);
      }
      if (g.failures.size() > 5)
        md += fmt::format("  - and {} more (summary.json lists all)\n", g.failures.size() - 5);
    }
  }
  md += "\n## Runs\n\n";
  for (const std::string& r : s.runs) md += fmt::format("- [{}]({}/report.html)\n", r, r);
  return md;
}

json summaryJson(const CampaignSummary& s, const std::vector<CampaignGroup>& groups) {
  json backends = json::object();
  for (const auto& [backend, c] : s.backends)
    backends[backend] = {{"pairs", c.total()}, {"pass", c.pass},   {"warn", c.warn},
                         {"fail", c.fail},     {"error", c.error}, {"flake", c.flake}};
  json jg = json::array();
  for (const CampaignGroup& g : groups) {
    const auto& files = filesOf(s, g);
    json failures = json::array();
    for (const CampaignFailure* f : g.failures) failures.push_back(f->id);
    json expectation = {{"checked", files.expectation.checked}};
    expectation["entry"] = files.expectation.checked && !files.expectation.entry.empty()
                               ? json(files.expectation.entry)
                               : json(nullptr);
    jg.push_back({{"id", g.id},
                  {"signature", g.signature},
                  {"expected", g.expected},
                  {"actual", g.actual},
                  {"class", g.cls},
                  {"kind", g.kind},
                  {"involved", g.involved},
                  {"count", g.failures.size()},
                  {"failures", failures},
                  {"common_tags", g.common_tags},
                  {"reproducer", files.reproducer.empty() ? json(nullptr) : json(files.reproducer)},
                  {"reproducer_fails", g.reproducer && g.reproducer->reproduces
                                           ? json(*g.reproducer->reproduces)
                                           : json(nullptr)},
                  {"command", files.command.empty() ? json(nullptr) : json(files.command)},
                  {"expectation", expectation}});
  }
  json failures = json::array();
  for (const CampaignFailure& f : s.failures) {
    json j = toJson(f);
    j["signature"] = signatureOf(f);
    failures.push_back(j);
  }
  return {{"format", kCampaignFormat},
          {"command", s.command},
          {"options", s.options},
          {"complete", s.complete},
          {"scenes", {{"total", s.scenes_total}, {"run", s.scenes_run}}},
          {"failures_done", s.failures_done},
          {"backends", backends},
          {"groups", jg},
          {"failures", failures},
          {"runs", s.runs},
          {"variants", s.variants.is_null() ? json::object() : s.variants},
          {"exit_code", campaignExitCode(s, groups)}};
}

std::string indexHtml(const CampaignSummary& s, const std::vector<CampaignGroup>& groups) {
  std::string page =
      "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>rastercheck campaign</title>"
      "<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}"
      "td,th{border:1px solid #ccc;padding:4px 8px;text-align:left}code{font-size:90%}</style>"
      "</head><body>\n<h1>rastercheck campaign</h1>\n";
  page += fmt::format(
      "<p>{} of {} scenes run, {} failures in {} groups{}. "
      "<a href=\"summary.md\">summary.md</a>, "
      "<a href=\"summary.json\">summary.json</a>, "
      "<a href=\"campaign.json\">campaign.json</a>.</p>\n",
      s.scenes_run, s.scenes_total, s.failures.size(), groups.size(),
      s.complete ? "" : " (incomplete)");
  page +=
      "<h2>Groups</h2>\n<table><tr><th>group</th><th>signature</th><th>failures</th>"
      "<th>reproducer</th><th>examples</th></tr>\n";
  for (const CampaignGroup& g : groups) {
    const auto& files = filesOf(s, g);
    std::string examples;
    for (std::size_t i = 0; i < g.failures.size() && i < 5; ++i) {
      const CampaignFailure& f = *g.failures[i];
      examples += f.images.empty() ? htmlEscape(f.fixture)
                                   : fmt::format("<a href=\"{}\">{}</a>", htmlEscape(f.images),
                                                 htmlEscape(f.fixture));
      examples += "<br>";
    }
    page += fmt::format(
        "<tr><td>{}</td><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td></tr>\n", g.id,
        htmlEscape(g.signature), g.failures.size(),
        files.reproducer.empty()
            ? std::string("none")
            : fmt::format("<a href=\"{}\">{}</a><br><code>{}</code>", htmlEscape(files.reproducer),
                          htmlEscape(files.reproducer), htmlEscape(files.command)),
        examples);
  }
  page += "</table>\n<h2>Runs</h2>\n<ul>\n";
  for (const std::string& r : s.runs)
    page +=
        fmt::format("<li><a href=\"{}/report.html\">{}</a></li>\n", htmlEscape(r), htmlEscape(r));
  page += "</ul>\n</body></html>\n";
  return page;
}

}  // namespace rc
