// The GLSL constants that mirror C++ enums (shading mode, specular model, attenuation,
// light type) are generated from those enums, and the shaders use nothing else: a literal
// compared with one of those uniforms, or a constant the generator does not make, fails
// here (no GL driver needed: only the program text is read).
#include <regex>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "fixtures/scene.h"
#include "gl_backend/shaders.h"

namespace rc::gl {
namespace {

int defineValue(const std::string& source, const std::string& name) {
  const std::regex re("#define " + name + " (-?[0-9]+)\n");
  std::smatch m;
  if (!std::regex_search(source, m, re)) return -1000;
  return std::stoi(m[1].str());
}

TEST(ShaderSource, EnumConstantsAreTheCppValues) {
  const ProgramSource p = programSource(4);
  for (const std::string* stage : {&p.vertex, &p.fragment}) {
    EXPECT_EQ(defineValue(*stage, "RC_SHADING_FLAT"), static_cast<int>(Shading::Flat));
    EXPECT_EQ(defineValue(*stage, "RC_SHADING_GOURAUD"), static_cast<int>(Shading::Gouraud));
    EXPECT_EQ(defineValue(*stage, "RC_SHADING_PHONG"), static_cast<int>(Shading::Phong));
    EXPECT_EQ(defineValue(*stage, "RC_SPECULAR_PHONG"), static_cast<int>(SpecularModel::Phong));
    EXPECT_EQ(defineValue(*stage, "RC_SPECULAR_BLINN_PHONG"),
              static_cast<int>(SpecularModel::BlinnPhong));
    EXPECT_EQ(defineValue(*stage, "RC_ATTENUATION_NONE"), static_cast<int>(Attenuation::None));
    EXPECT_EQ(defineValue(*stage, "RC_ATTENUATION_INVERSE"),
              static_cast<int>(Attenuation::Inverse));
    EXPECT_EQ(defineValue(*stage, "RC_ATTENUATION_INVERSE_SQUARE"),
              static_cast<int>(Attenuation::InverseSquare));
    EXPECT_EQ(defineValue(*stage, "RC_LIGHT_POINT"), static_cast<int>(LightType::Point));
    EXPECT_EQ(defineValue(*stage, "RC_LIGHT_DIRECTIONAL"),
              static_cast<int>(LightType::Directional));
  }
  // The uniforms carry the C++ value itself.
  EXPECT_EQ(uniformValue(Shading::Gouraud), static_cast<int>(Shading::Gouraud));
  EXPECT_EQ(uniformValue(LightType::Directional), static_cast<int>(LightType::Directional));
}

TEST(ShaderSource, EveryGeneratedNameIsDistinctAndEachEnumCoversItsValues) {
  std::set<std::string> names;
  std::set<std::pair<std::string, int>> values;  // (enum prefix, value)
  for (const GlslEnumDefine& d : glslEnumDefines()) {
    EXPECT_TRUE(names.insert(d.name).second) << d.name;
    const std::string prefix = d.name.substr(0, d.name.find('_', 3));
    EXPECT_TRUE(values.insert({prefix, d.value}).second) << d.name << " repeats a value";
  }
  EXPECT_EQ(names.size(), 10u);
}

// Tests the shader text outside comments and #define lines.
std::string code(const std::string& source) {
  std::string out;
  std::size_t pos = 0;
  while (pos < source.size()) {
    std::size_t end = source.find('\n', pos);
    if (end == std::string::npos) end = source.size();
    std::string line = source.substr(pos, end - pos);
    if (const std::size_t c = line.find("//"); c != std::string::npos) line.resize(c);
    if (line.rfind("#define", 0) != 0) out += line + '\n';
    pos = end + 1;
  }
  return out;
}

TEST(ShaderSource, EnumUniformsAreComparedOnlyWithGeneratedNames) {
  ShaderFaults all;
  all.depth_bias = all.shift_x = all.texel_offset = true;
  for (const ProgramSource& p :
       {programSource(1), programSource(8, all), programSource(2, {}, true)}) {
    for (const std::string* stage : {&p.vertex, &p.fragment}) {
      const std::string body = code(*stage);
      // No literal on either side of ==/!= with an enum-carrying uniform.
      const std::regex literal(
          R"((u_shading|u_specular_model|u_attenuation|u_light_type\s*\[[^\]]*\])\s*[=!]=\s*-?[0-9])"
          R"(|-?[0-9]+\s*[=!]=\s*(u_shading|u_specular_model|u_attenuation|u_light_type))");
      EXPECT_FALSE(std::regex_search(body, literal)) << body;
      // Every RC_ name the code uses is generated (or one of the program's own defines).
      std::set<std::string> known = {"RC_MAX_LIGHTS", "RC_SHADOW_LOOKUP"};
      for (const GlslEnumDefine& d : glslEnumDefines()) known.insert(d.name);
      const std::regex name(R"(\bRC_[A-Z_]+\b)");
      for (auto it = std::sregex_iterator(body.begin(), body.end(), name);
           it != std::sregex_iterator(); ++it) {
        const std::string n = it->str();
        if (n.rfind("RC_FAULT_", 0) == 0) continue;  // test-only #ifdef switches
        EXPECT_TRUE(known.count(n)) << n << " is not generated from a C++ enum";
      }
      // And the uniforms are there: the checks above looked at the real program.
      EXPECT_NE(body.find("u_light_type"), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace rc::gl
