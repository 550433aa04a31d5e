// junit.xml: one <testcase> per fixture x pair (classname = fixture, name = "expected vs
// actual"), in the dialect Jenkins, GitLab and GitHub test reporters read. A failing pair
// carries <failure> (message: the failing classes, counts and worst pixel), an error row
// <error>, and a warning passes with the reasons in <system-out>.
#include <sstream>

#include <fmt/format.h>
#include <pugixml.hpp>

#include "compare/report.h"
#include "compare/report_text.h"

namespace rc {
namespace {

std::string classLines(const PairResult& r) {
  return visibilityText(r) + "\n" + depthText(r) + "\n" + shadingText(r) + "\n";
}

std::string failingClasses(const PairResult& r) {
  std::string out;
  auto add = [&](Status s, const char* name) {
    if (s != r.status) return;
    if (!out.empty()) out += ",";
    out += name;
  };
  add(r.visibility.status, "visibility");
  add(r.depth.status, "depth");
  add(r.shading.status, "shading");
  return out;
}

// XML 1.0 cannot carry control characters other than tab and newline, even escaped.
std::string xmlSafe(std::string text) {
  for (char& ch : text) {
    const auto u = static_cast<unsigned char>(ch);
    if (u < 0x20 && ch != '\n' && ch != '\t' && ch != '\r') ch = '?';
  }
  return text;
}

}  // namespace

std::string junitXml(const Report& report) {
  const ReportSummary s = report.summary();
  double total_seconds = 0.0;
  for (const PairResult& r : report.results) total_seconds += r.seconds;

  pugi::xml_document doc;
  pugi::xml_node suites = doc.append_child("testsuites");
  suites.append_attribute("name") = report.tool_name.c_str();
  suites.append_attribute("tests") = static_cast<unsigned long long>(s.total());
  // A known failure (an expectation covers it) is reported as skipped, as test runners
  // report expected failures, so CI stays green on it.
  suites.append_attribute("failures") = static_cast<unsigned long long>(s.fail - s.known_fail);
  suites.append_attribute("errors") = static_cast<unsigned long long>(s.error);
  suites.append_attribute("time") = fmt::format("{:.6f}", total_seconds).c_str();
  pugi::xml_node suite = suites.append_child("testsuite");
  suite.append_attribute("name") = report.tool_name.c_str();
  suite.append_attribute("tests") = static_cast<unsigned long long>(s.total());
  suite.append_attribute("failures") = static_cast<unsigned long long>(s.fail - s.known_fail);
  suite.append_attribute("errors") = static_cast<unsigned long long>(s.error);
  const std::uint64_t skipped = s.known_fail + s.not_supported + s.flake;
  suite.append_attribute("skipped") = static_cast<unsigned long long>(skipped);
  suite.append_attribute("time") = fmt::format("{:.6f}", total_seconds).c_str();
  pugi::xml_node props = suite.append_child("properties");
  pugi::xml_node version = props.append_child("property");
  version.append_attribute("name") = "version";
  version.append_attribute("value") = report.tool_version.c_str();
  if (!report.command.empty()) {
    pugi::xml_node command = props.append_child("property");
    command.append_attribute("name") = "command";
    command.append_attribute("value") = report.command.c_str();
  }

  for (const PairResult& r : report.results) {
    pugi::xml_node tc = suite.append_child("testcase");
    tc.append_attribute("classname") = (r.fixture.empty() ? "(unnamed)" : r.fixture).c_str();
    tc.append_attribute("name") = fmt::format("{} vs {}", r.expected, r.actual).c_str();
    tc.append_attribute("time") = fmt::format("{:.6f}", r.seconds).c_str();
    switch (r.status) {
      case Status::NotSupported: {
        pugi::xml_node k = tc.append_child("skipped");
        k.append_attribute("type") = "not supported";
        k.append_attribute("message") = ("not supported: " + r.error).c_str();
        break;
      }
      case Status::Flake: {
        // Not a verdict on the driver's output: reported as skipped (with the reason), as
        // deqp-runner counts a flake as a success, so that CI does not go red on it.
        pugi::xml_node k = tc.append_child("skipped");
        k.append_attribute("type") = "flake";
        k.append_attribute("message") = describe(r).c_str();
        break;
      }
      case Status::Error: {
        pugi::xml_node e = tc.append_child("error");
        e.append_attribute("message") = r.error.c_str();
        e.append_attribute("type") = "backend";
        break;
      }
      case Status::Fail: {
        if (!r.known.empty()) {
          pugi::xml_node k = tc.append_child("skipped");
          k.append_attribute("type") = "known failure";
          k.append_attribute("message") = describe(r).c_str();
          k.append_child(pugi::node_pcdata).set_value(classLines(r).c_str());
          break;
        }
        pugi::xml_node f = tc.append_child("failure");
        f.append_attribute("message") = describe(r).c_str();
        f.append_attribute("type") = failingClasses(r).c_str();
        f.append_child(pugi::node_pcdata).set_value(classLines(r).c_str());
        break;
      }
      case Status::Warn:
        tc.append_child("system-out")
            .append_child(pugi::node_pcdata)
            .set_value((describe(r) + "\n" + classLines(r)).c_str());
        break;
      case Status::Pass:
        tc.append_child("system-out")
            .append_child(pugi::node_pcdata)
            .set_value(classLines(r).c_str());
        break;
    }
  }
  std::ostringstream out;
  doc.save(out, "  ", pugi::format_default | pugi::format_no_declaration);
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n" + xmlSafe(out.str());
}

}  // namespace rc
