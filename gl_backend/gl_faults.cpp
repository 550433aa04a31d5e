// Parsing and printing the test-only fault list of RASTERCHECK_GL_FAULT: see gl_testing.h.
#include <charconv>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "fixtures/errors.h"
#include "gl_backend/gl_testing.h"

namespace rc::gl::testing {
namespace {

constexpr const char* kValidFaults =
    "drop_primitive=ID, depth_bias=STEPS, light_scale=F, no_inverse_transpose, shift_x=PX, "
    "shader_compile_error, move_vertex=ID, move_line_end=ID, move_point=ID, texel_offset=N, "
    "blend_factor=one|swapped, "
    "depth_func=inverted, stencil_op=shifted, blend_function=shifted, scissor_shift=N, "
    "lod_shift=N, lod_weight=inverted, shadow_shift=N, shadow_compare=inverted, "
    "shadow_bias=dropped, hang=FIXTURE|*, crash=FIXTURE|*, flaky=FIXTURE|*, hang_once=FIXTURE|*";

[[noreturn]] void badFault(std::string_view entry, std::string_view why) {
  throw InputError(
      fmt::format("{}: '{}': {} (valid: {})", kFaultVariable, entry, why, kValidFaults));
}

template <typename T>
T number(std::string_view entry, std::string_view value) {
  T out{};
  const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), out);
  if (value.empty() || ec != std::errc() || end != value.data() + value.size())
    badFault(entry, "not a number");
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(out)) badFault(entry, "not a finite number");
  }
  return out;
}

}  // namespace

bool Faults::any() const {
  return drop_primitive != 0 || depth_bias_steps != 0 || light_scale != 1.0 ||
         no_inverse_transpose || shift_x_px != 0.0 || shader_compile_error || move_vertex != 0 ||
         move_line_end != 0 || move_point != 0 || texel_offset != 0.0 ||
         blend_factor != Blend::Correct || depth_func_inverted || stencil_op_shifted ||
         blend_function_shifted || scissor_shift != 0 || lod_shift != 0.0 || lod_weight_inverted ||
         shadow_shift != 0.0 || shadow_compare_inverted || shadow_bias_dropped || !hang.empty() ||
         !crash.empty() || !flaky.empty() || !hang_once.empty();
}

bool Faults::hangs(const std::string& fixture) const { return hang == "*" || hang == fixture; }
bool Faults::crashes(const std::string& fixture) const { return crash == "*" || crash == fixture; }
bool Faults::flakes(const std::string& fixture) const { return flaky == "*" || flaky == fixture; }
bool Faults::hangsOnce(const std::string& fixture) const {
  return hang_once == "*" || hang_once == fixture;
}

std::string Faults::describe() const {
  std::vector<std::string> parts;
  if (drop_primitive != 0) parts.push_back(fmt::format("drop_primitive={}", drop_primitive));
  if (depth_bias_steps != 0) parts.push_back(fmt::format("depth_bias={}", depth_bias_steps));
  if (light_scale != 1.0) parts.push_back(fmt::format("light_scale={}", light_scale));
  if (no_inverse_transpose) parts.emplace_back("no_inverse_transpose");
  if (shift_x_px != 0.0) parts.push_back(fmt::format("shift_x={}", shift_x_px));
  if (shader_compile_error) parts.emplace_back("shader_compile_error");
  if (move_vertex != 0) parts.push_back(fmt::format("move_vertex={}", move_vertex));
  if (move_line_end != 0) parts.push_back(fmt::format("move_line_end={}", move_line_end));
  if (move_point != 0) parts.push_back(fmt::format("move_point={}", move_point));
  if (texel_offset != 0.0) parts.push_back(fmt::format("texel_offset={}", texel_offset));
  if (blend_factor != Blend::Correct)
    parts.push_back(fmt::format("blend_factor={}", blend_factor == Blend::One ? "one" : "swapped"));
  if (depth_func_inverted) parts.emplace_back("depth_func=inverted");
  if (stencil_op_shifted) parts.emplace_back("stencil_op=shifted");
  if (blend_function_shifted) parts.emplace_back("blend_function=shifted");
  if (scissor_shift != 0) parts.push_back(fmt::format("scissor_shift={}", scissor_shift));
  if (lod_shift != 0.0) parts.push_back(fmt::format("lod_shift={}", lod_shift));
  if (lod_weight_inverted) parts.emplace_back("lod_weight=inverted");
  if (shadow_shift != 0.0) parts.push_back(fmt::format("shadow_shift={}", shadow_shift));
  if (shadow_compare_inverted) parts.emplace_back("shadow_compare=inverted");
  if (shadow_bias_dropped) parts.emplace_back("shadow_bias=dropped");
  if (!hang.empty()) parts.push_back("hang=" + hang);
  if (!crash.empty()) parts.push_back("crash=" + crash);
  if (!flaky.empty()) parts.push_back("flaky=" + flaky);
  if (!hang_once.empty()) parts.push_back("hang_once=" + hang_once);
  return fmt::format("{}", fmt::join(parts, ","));
}

Faults parseFaults(std::string_view text) {
  Faults f;
  while (!text.empty()) {
    const std::size_t comma = text.find(',');
    const std::string_view entry = text.substr(0, comma);
    text = comma == std::string_view::npos ? std::string_view{} : text.substr(comma + 1);
    if (entry.empty()) continue;
    const std::size_t eq = entry.find('=');
    const std::string_view name = entry.substr(0, eq);
    const bool has_value = eq != std::string_view::npos;
    const std::string_view value = has_value ? entry.substr(eq + 1) : std::string_view{};
    const bool flag = name == "no_inverse_transpose" || name == "shader_compile_error";
    const bool valued = name == "drop_primitive" || name == "depth_bias" || name == "light_scale" ||
                        name == "shift_x" || name == "move_vertex" || name == "texel_offset" ||
                        name == "move_line_end" || name == "move_point" || name == "blend_factor" ||
                        name == "hang" || name == "crash" || name == "flaky" ||
                        name == "hang_once" || name == "depth_func" || name == "stencil_op" ||
                        name == "blend_function" || name == "scissor_shift" ||
                        name == "lod_shift" || name == "lod_weight" || name == "shadow_shift" ||
                        name == "shadow_compare" || name == "shadow_bias";
    if (!flag && !valued) badFault(entry, "unknown fault");
    if (flag == has_value) badFault(entry, flag ? "takes no value" : "needs a value (NAME=VALUE)");
    if (name == "drop_primitive") {
      f.drop_primitive = number<std::uint32_t>(entry, value);
      if (f.drop_primitive == 0) badFault(entry, "primitive ids start at 1");
    } else if (name == "depth_bias") {
      f.depth_bias_steps = number<int>(entry, value);
    } else if (name == "light_scale") {
      f.light_scale = number<double>(entry, value);
    } else if (name == "shift_x") {
      f.shift_x_px = number<double>(entry, value);
    } else if (name == "move_vertex") {
      f.move_vertex = number<std::uint32_t>(entry, value);
      if (f.move_vertex == 0) badFault(entry, "primitive ids start at 1");
    } else if (name == "move_line_end") {
      f.move_line_end = number<std::uint32_t>(entry, value);
      if (f.move_line_end == 0) badFault(entry, "primitive ids start at 1");
    } else if (name == "move_point") {
      f.move_point = number<std::uint32_t>(entry, value);
      if (f.move_point == 0) badFault(entry, "primitive ids start at 1");
    } else if (name == "texel_offset") {
      f.texel_offset = number<double>(entry, value);
    } else if (name == "blend_factor") {
      if (value == "one") {
        f.blend_factor = Faults::Blend::One;
      } else if (value == "swapped") {
        f.blend_factor = Faults::Blend::Swapped;
      } else {
        badFault(entry, "must be one or swapped");
      }
    } else if (name == "depth_func") {
      if (value != "inverted") badFault(entry, "must be inverted");
      f.depth_func_inverted = true;
    } else if (name == "stencil_op") {
      if (value != "shifted") badFault(entry, "must be shifted");
      f.stencil_op_shifted = true;
    } else if (name == "blend_function") {
      if (value != "shifted") badFault(entry, "must be shifted");
      f.blend_function_shifted = true;
    } else if (name == "scissor_shift") {
      f.scissor_shift = number<int>(entry, value);
    } else if (name == "lod_shift") {
      f.lod_shift = number<double>(entry, value);
    } else if (name == "lod_weight") {
      if (value != "inverted") badFault(entry, "must be inverted");
      f.lod_weight_inverted = true;
    } else if (name == "shadow_shift") {
      f.shadow_shift = number<double>(entry, value);
    } else if (name == "shadow_compare") {
      if (value != "inverted") badFault(entry, "must be inverted");
      f.shadow_compare_inverted = true;
    } else if (name == "shadow_bias") {
      if (value != "dropped") badFault(entry, "must be dropped");
      f.shadow_bias_dropped = true;
    } else if (name == "hang" || name == "crash" || name == "flaky" || name == "hang_once") {
      if (value.empty()) badFault(entry, "needs a fixture name or *");
      (name == "hang"    ? f.hang
       : name == "crash" ? f.crash
       : name == "flaky" ? f.flaky
                         : f.hang_once) = std::string(value);
    } else if (name == "no_inverse_transpose") {
      f.no_inverse_transpose = true;
    } else {
      f.shader_compile_error = true;
    }
  }
  return f;
}

}  // namespace rc::gl::testing
