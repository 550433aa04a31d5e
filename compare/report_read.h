// report.json read back: checked access to its fields (every error names the file and
// the JSON path) and whole rows back into PairResult, for the commands that work on
// finished runs (`accuracy`, `merge`, `diff-runs`). The inverse of report.h's toJson.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "compare/compare.h"
#include "compare/report.h"

namespace rc {

// The file as JSON. Throws InputError when it cannot be read or is not JSON.
nlohmann::json readJsonFile(const std::filesystem::path& file);

// Reads fields of one report.json; every error names the file and the JSON path.
class ReportReader {
 public:
  explicit ReportReader(std::filesystem::path file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& path, const std::string& what) const;

  const nlohmann::json& member(const nlohmann::json& j, const char* key,
                               const std::string& path) const;
  std::string text(const nlohmann::json& j, const char* key, const std::string& path) const;
  // Numbers the writer may leave out or write as null (non-finite): 0 then.
  double number(const nlohmann::json& j, const char* key, const std::string& path) const;
  std::uint64_t count(const nlohmann::json& j, const char* key, const std::string& path) const;
  std::optional<double> optionalNumber(const nlohmann::json& j, const char* key,
                                       const std::string& path) const;
  std::optional<PixelRef> pixel(const nlohmann::json& j, const char* key,
                                const std::string& path) const;
  Status status(const nlohmann::json& j, const char* key, const std::string& path) const;

  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
};

// One results[] row (`at` is its JSON path) back into the PairResult toJson wrote it from.
// Image paths are resolved against report_dir. Numbers written as null (non-finite) come
// back as NaN where the row has a pixel for them (+inf for worst_edge_dist), else 0.
// Histograms come back with the counts of their coarse bins.
PairResult pairResultFromJson(const ReportReader& reader, const nlohmann::json& row,
                              const std::string& at, const std::filesystem::path& report_dir);

// A whole report.json: tool, command, results, variants and shard. Throws InputError.
Report readReportFile(const std::filesystem::path& file);

}  // namespace rc
