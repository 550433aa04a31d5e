// Inside compare/: the parts of report.html that html.cpp puts together: the style sheet
// (html_style.cpp), the script (html_script.cpp), the tables above the pairs
// (html_overview.cpp) and what each pair's section shows (html_pair.cpp).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "compare/compare.h"
#include "compare/report.h"
#include "compare/report_text.h"

namespace rc::detail {

// Text for the page, and a status as a coloured badge.
inline std::string esc(std::string_view s) { return htmlEscape(s); }

inline std::string badge(Status s) {
  return fmt::format("<span class=\"badge {0}\">{0}</span>", toString(s));
}

// The style sheet, and the legends' colours from the tables the images use (html_style.cpp).
extern const char* const kStyle;
std::string legendStyle();

// The script that builds the rows and sections from the page's data (html_script.cpp).
extern const char* const kScript;

// A number as the page's data holds it, and what a pair's section shows (html_pair.cpp).
nlohmann::json jnum(double v);
nlohmann::json sectionData(const PairResult& r, const std::filesystem::path& report_dir, bool full);

// The tables above the pairs (html_overview.cpp).

// The column a pair belongs to: its actual backend, labelled "actual vs expected" when the
// pairs do not all share one expected side (driver-vs-driver runs next to reference runs).
struct Columns {
  bool one_expected = true;
  std::vector<std::string> names;
  std::vector<std::size_t> of;  // per result
};

Columns columnsOf(const Report& report);
// The fixture x backend matrix, the verdict counts per backend column, the variants table.
std::string matrix(const Report& report, const Columns& columns);
std::string backendCounts(const Report& report, const Columns& columns);
std::string variantsTable(const Report& report);

}  // namespace rc::detail
