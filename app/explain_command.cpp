// `rastercheck explain SCENE --pixel X,Y [--backends SPEC,...] [--json]`: the reference's
// history of one pixel, like RenderDoc's pixel history: every fragment that reached it in
// draw order with its depth test and every term of its colour, what the reference stored
// there in the end with its uncertainty channels, and what each listed backend has there
// with the comparator's class. The JSON document is built first and the text story is
// told from it, so the two cannot disagree. docs/explain.md documents every key.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <iostream>
#include <limits>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/backends.h"
#include "app/commands.h"
#include "app/debug_support.h"
#include "app/report_support.h"
#include "compare/compare.h"
#include "fixtures/errors.h"
#include "fixtures/loader.h"
#include "fixtures/resource_estimate.h"
#include "fixtures/scene_logic.h"
#include "reference/fragment_ops.h"
#include "reference/shading.h"
#include "reference/vertex_stage.h"

namespace rc {
namespace fs = std::filesystem;
namespace {

using Json = nlohmann::ordered_json;

inline constexpr const char* kExplainFormat = "rastercheck-explain/1";

Json num(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }
Json vec(const glm::dvec3& v) { return Json::array({num(v.x), num(v.y), num(v.z)}); }
Json vec(const glm::dvec4& v) { return Json::array({num(v.x), num(v.y), num(v.z), num(v.w)}); }

glm::ivec2 parsePixel(const std::string& text) {
  const std::size_t comma = text.find(',');
  glm::ivec2 p(0);
  auto parse = [](std::string_view s, int& out) {
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && ptr == s.data() + s.size();
  };
  if (comma == std::string::npos || !parse(std::string_view(text).substr(0, comma), p.x) ||
      !parse(std::string_view(text).substr(comma + 1), p.y))
    throw InputError(
        fmt::format("--pixel '{}': expected X,Y (two integers, image coordinates, "
                    "origin top-left)",
                    text));
  return p;
}

const char* lightType(const Light& l) {
  return l.type == LightType::Point ? "point" : "directional";
}

// The factors that produced one light's terms at one shaded point, by the formulas of
// reference/shading.h (recomputed here; the terms themselves come from the trace).
Json lightFactors(const Scene& scene, const Light& light, double shininess, const glm::dvec3& p,
                  const glm::dvec3& n, double weight) {
  Json f = {{"weight", weight}};
  glm::dvec3 l(0.0);
  double att = 1.0;
  double distance = std::numeric_limits<double>::quiet_NaN();
  bool contributes = n != glm::dvec3(0.0);
  if (light.type == LightType::Directional) {
    l = -ref::safeNormalize(light.direction);
  } else {
    const glm::dvec3 to_light = light.position - p;
    distance = std::sqrt(glm::dot(to_light, to_light));
    if (distance > 0.0) {
      l = to_light * (1.0 / distance);
      if (scene.state.attenuation == Attenuation::Inverse) att = 1.0 / distance;
      if (scene.state.attenuation == Attenuation::InverseSquare) att = 1.0 / (distance * distance);
    } else {
      contributes = false;  // the light sits at the shaded point
    }
  }
  f["distance"] = num(distance);
  f["attenuation"] = num(att);
  const glm::dvec3 v = ref::safeNormalize(scene.camera.eye - p);
  const double n_dot_l = glm::dot(n, l);
  double base = 0.0;
  Json n_dot_h = nullptr;
  Json r_dot_v = nullptr;
  if (scene.state.specular_model == SpecularModel::BlinnPhong) {
    const double d = glm::dot(n, ref::safeNormalize(l + v));
    n_dot_h = num(d);
    base = std::max(0.0, d);
  } else {
    const double d = glm::dot(2.0 * n_dot_l * n - l, v);
    r_dot_v = num(d);
    base = std::max(0.0, d);
  }
  f["n_dot_l"] = num(n_dot_l);
  f["n_dot_h"] = n_dot_h;
  f["r_dot_v"] = r_dot_v;
  f["specular_power"] = num(ref::specularPower(base, shininess));
  f["contributes"] = contributes;
  return f;
}

struct Context {
  const Scene& scene;
  ref::Lighting lighting;
  std::vector<PrimitiveRef> primitives;                                   // by id - 1
  std::map<std::uint32_t, std::vector<ref::TransformedVertex>> vertices;  // per object
  std::map<std::uint32_t, std::size_t> pass_of;                           // id -> draw pass
  std::vector<DrawPass> passes;

  const std::vector<ref::TransformedVertex>& objectVertices(std::uint32_t object) {
    auto it = vertices.find(object);
    if (it == vertices.end()) {
      std::vector<ref::TransformedVertex> v;
      ref::transformObject(scene.objects[object], ref::cameraTransform(scene), v);
      it = vertices.emplace(object, std::move(v)).first;
    }
    return it->second;
  }
};

// The shading block of one fragment: the terms from the trace, the points they were
// evaluated at (with the per-point sums the colour is built from) and the factors.
Json shadingJson(Context& ctx, const FragmentTrace& f) {
  const Scene& scene = ctx.scene;
  const PrimitiveRef& prim = ctx.primitives[f.primitive - 1];
  const Object& obj = scene.objects[prim.object];
  const Material& material = scene.materials[obj.material];
  const auto& tri = obj.mesh.triangles[prim.triangle];
  const std::vector<ref::TransformedVertex>& verts = ctx.objectVertices(prim.object);
  const ref::TransformedVertex* v[3] = {&verts[tri[0]], &verts[tri[1]], &verts[tri[2]]};
  const glm::dvec3& b = f.barycentric;

  struct Point {
    double weight;
    glm::dvec3 position;
    glm::dvec3 normal;
  };
  std::vector<Point> points;
  const char* at = "fragment";
  switch (scene.state.shading) {
    case Shading::Flat: {
      at = "centroid";
      const glm::dvec3& p0 = v[0]->world;
      const glm::dvec3& p1 = v[1]->world;
      const glm::dvec3& p2 = v[2]->world;
      points.push_back(
          {1.0, (p0 + p1 + p2) / 3.0, ref::safeNormalize(glm::cross(p1 - p0, p2 - p0))});
      break;
    }
    case Shading::Gouraud:
      at = "vertices";
      for (int k = 0; k < 3; ++k) points.push_back({b[k], v[k]->world, v[k]->normal});
      break;
    case Shading::Phong:
      points.push_back(
          {1.0, b.x * v[0]->world + b.y * v[1]->world + b.z * v[2]->world,
           ref::safeNormalize(b.x * v[0]->normal + b.y * v[1]->normal + b.z * v[2]->normal)});
      break;
  }

  Json j = {{"model", toString(scene.state.shading)},
            {"specular_model", toString(scene.state.specular_model)},
            {"evaluated_at", at}};
  Json pts = Json::array();
  for (const Point& p : points) {
    const ref::LitColor lit = ref::shadePoint(ctx.lighting, material, p.position, p.normal);
    pts.push_back({{"weight", p.weight},
                   {"position", vec(p.position)},
                   {"normal", vec(p.normal)},
                   {"ambient_diffuse", vec(lit.ambient_diffuse)},
                   {"specular", vec(lit.specular)}});
  }
  j["points"] = pts;
  j["ambient"] = vec(f.shading.ambient);
  Json lights = Json::array();
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& light = scene.lights[i];
    Json factors = Json::array();
    for (const Point& p : points) {
      factors.push_back(
          lightFactors(scene, light, material.shininess, p.position, p.normal, p.weight));
    }
    const LightTerms terms = i < f.shading.lights.size() ? f.shading.lights[i] : LightTerms{};
    lights.push_back({{"index", i},
                      {"type", lightType(light)},
                      {"color", vec(light.color)},
                      {"intensity", num(light.intensity)},
                      {"diffuse", vec(terms.diffuse)},
                      {"specular", vec(terms.specular)},
                      {"factors", factors}});
  }
  j["lights"] = lights;
  if (material.texture) {
    const glm::dvec2 uv = b.x * v[0]->uv + b.y * v[1]->uv + b.z * v[2]->uv;
    j["texture"] = vec(f.shading.texture);
    j["uv"] = Json::array({num(uv.x), num(uv.y)});
  } else {
    j["texture"] = nullptr;
    j["uv"] = nullptr;
  }
  j["opacity"] = num(material.opacity);
  j["color"] = vec(f.shading.color);
  return j;
}

std::string passKind(const Scene& scene, const DrawPass& pass, bool force_painter) {
  if (pass.blend) return "transparent";
  if (force_painter || scene.state.visibility == Visibility::Painter) return "painter";
  return "opaque";
}

// ---- the backends -------------------------------------------------------------------

// Stable names for the JSON (toString(PixelClass) is for people).
const char* classKey(PixelClass c) {
  switch (c) {
    case PixelClass::Background:
      return "background";
    case PixelClass::Match:
      return "match";
    case PixelClass::MissingAmbiguous:
      return "missing_ambiguous";
    case PixelClass::MissingHard:
      return "missing_hard";
    case PixelClass::ExtraAmbiguous:
      return "extra_ambiguous";
    case PixelClass::ExtraHard:
      return "extra_hard";
    case PixelClass::WrongAmbiguous:
      return "wrong_primitive_ambiguous";
    case PixelClass::WrongHard:
      return "wrong_primitive_hard";
  }
  return "?";
}

Json backendJson(const BackendSpec& spec, const Frame& reference, const Frame& frame,
                 const Scene& scene, const CommandLineTolerances& cli, std::size_t i) {
  Json j = {{"backend", spec.text}};
  if (frame.meta.contains("renderer")) j["renderer"] = frame.meta["renderer"];
  j["subpixel_bits"] =
      frame.meta.contains("subpixel_bits") ? Json(frame.meta["subpixel_bits"]) : Json(nullptr);
  j["id"] = frame.id[i];
  j["color"] = Json::array({num(frame.color[4 * i]), num(frame.color[4 * i + 1]),
                            num(frame.color[4 * i + 2]), num(frame.color[4 * i + 3])});
  j["depth"] = num(frame.depth[i]);

  const Tolerances tol = pairTolerances(reference, frame, scene.tolerance, cli);
  ClassMaps maps;
  const PairResult r = compareFrames(reference, frame, reference, tol, &maps);
  const PixelClass cls = maps.pixel_class[i];
  Json c = {
      {"visibility", classKey(cls)},
      {"ambiguous", cls == PixelClass::MissingAmbiguous || cls == PixelClass::ExtraAmbiguous ||
                        cls == PixelClass::WrongAmbiguous},
      {"band_px", num(r.visibility.band_px)}};
  if (cls == PixelClass::Match) {
    // The comparator works out a pixel's allowance only where the error exceeds the base
    // warn threshold (the maps hold 0 elsewhere); within it the pixel passes whatever the
    // allowance, and the base threshold is what is reported.
    const double steps = maps.depth_steps[i];
    const double warn_at = std::max<double>(maps.depth_tolerance[i], tol.depth.warn);
    const double fail_at = tol.depth.fail + (warn_at - tol.depth.warn);
    const Status depth_verdict = !(steps <= fail_at)   ? Status::Fail
                                 : !(steps <= warn_at) ? Status::Warn
                                                       : Status::Pass;
    c["depth"] = {{"steps", num(steps)},
                  {"warn_above", num(warn_at)},
                  {"fail_above", num(fail_at)},
                  {"verdict", toString(depth_verdict)}};
    const double shading = maps.shading_abs[i];
    // Over the base warn, the pixel's thresholds carry its allowance (value, gradient,
    // filtering) as the comparator computed it: warn + allowance, fail + the same.
    const double shading_warn_at = std::max<double>(maps.shading_tolerance[i], tol.shading.warn);
    const double shading_fail_at = tol.shading.fail + (shading_warn_at - tol.shading.warn);
    const Status shading_verdict = !(shading <= shading_fail_at)   ? Status::Fail
                                   : !(shading <= shading_warn_at) ? Status::Warn
                                                                   : Status::Pass;
    Json delta = Json::array();
    for (int k = 0; k < 4; ++k)
      delta.push_back(num((static_cast<double>(frame.color[4 * i + k]) -
                           static_cast<double>(reference.color[4 * i + k])) *
                          255.0));
    c["shading"] = {{"abs", num(shading)},
                    {"delta_rgba", delta},
                    {"warn_above", num(shading_warn_at)},
                    {"fail_above", num(shading_fail_at)},
                    {"verdict", toString(shading_verdict)}};
  } else {
    c["depth"] = nullptr;
    c["shading"] = nullptr;
  }
  j["class"] = c;
  j["pair_status"] = toString(r.status);
  return j;
}

// ---- the story ----------------------------------------------------------------------

std::string fmtNum(const Json& v) {
  if (v.is_null()) return "n/a";
  if (v.is_number_integer() || v.is_number_unsigned()) return v.dump();
  const double d = v.get<double>();
  if (d == std::floor(d) && std::fabs(d) < 1e15) return fmt::format("{:.0f}", d);
  return fmt::format("{:.7g}", d);
}
std::string fmtVec(const Json& v) {
  std::string out = "(";
  for (std::size_t k = 0; k < v.size(); ++k) out += (k ? ", " : "") + fmtNum(v[k]);
  return out + ")";
}

std::string story(const Json& doc) {
  std::string s;
  const Json& px = doc["pixel"];
  s +=
      fmt::format("{}: pixel ({},{}) in image coordinates, GL window ({},{}), of a {}x{} image\n",
                  doc["fixture"].get<std::string>(), px["image"][0].get<int>(),
                  px["image"][1].get<int>(), px["window"][0].get<int>(), px["window"][1].get<int>(),
                  doc["image"]["width"].get<int>(), doc["image"]["height"].get<int>());
  const Json& r = doc["reference"];
  s += fmt::format(
      "reference {}: {} subpixel bits, {} visibility, depth test {}, {} depth, {} "
      "colour, {} shading, {} specular\n",
      r["backend"].get<std::string>(), r["subpixel_bits"].get<int>(),
      r["visibility"].get<std::string>(), r["depth_test"].get<bool>() ? "on" : "off",
      r["depth_format"].get<std::string>(), r["color_format"].get<std::string>(),
      r["shading"].get<std::string>(), r["specular_model"].get<std::string>());
  const Json& frags = doc["fragments"];
  if (frags.empty()) {
    s += fmt::format(
        "No fragment reached this pixel: it keeps the clear colour {} and the clear "
        "depth {}.\n",
        fmtVec(doc["clear"]["color"]), fmtNum(doc["clear"]["depth"]));
  } else {
    s += fmt::format("{} fragment{} reached this pixel, in draw order:\n", frags.size(),
                     frags.size() == 1 ? "" : "s");
  }
  for (const Json& f : frags) {
    s += fmt::format(
        "\nfragment {}: primitive {}, triangle {} of '{}' ({} pass {}), barycentric "
        "{}\n",
        f["index"].get<int>(), f["primitive"].get<int>(), f["triangle"].get<int>(),
        f["object"].get<std::string>(), f["draw"]["kind"].get<std::string>(),
        f["draw"]["pass"].get<int>(), fmtVec(f["barycentric"]));
    const Json& d = f["depth"];
    s += fmt::format(
        "  window depth {}, stored as {}{}\n", fmtNum(d["window"]), fmtNum(d["stored"]),
        d["steps"].is_null()
            ? ""
            : fmt::format(" ({} steps of {})", fmtNum(d["steps"]), d["format"].get<std::string>()));
    const Json& t = f["depth_test"];
    const std::string against = t["against_source"] == "clear"
                                    ? fmt::format("the clear depth {}", fmtNum(t["against"]))
                                    : fmt::format("{} (stored by {})", fmtNum(t["against"]),
                                                  t["against_source"].get<std::string>());
    if (t["func"] == "always") {
      s += "  no depth test (ALWAYS)";
    } else if (t["result"] == "pass") {
      s += fmt::format("  passed the depth test against {}: {} < {}", against, fmtNum(d["stored"]),
                       fmtNum(t["against"]));
    } else {
      s += fmt::format("  failed the depth test against {}: {} is not < {}", against,
                       fmtNum(d["stored"]), fmtNum(t["against"]));
    }
    s += t["result"] == "pass"
             ? (t["write"].get<bool>() ? ", wrote its depth\n" : ", depth writes off\n")
             : ": discarded, nothing written\n";
    const Json& sh = f["shading"];
    s += fmt::format("  shading: {} at the {}", sh["model"].get<std::string>(),
                     sh["evaluated_at"].get<std::string>());
    if (sh["points"].size() == 1)
      s += fmt::format(" {} with normal {}", fmtVec(sh["points"][0]["position"]),
                       fmtVec(sh["points"][0]["normal"]));
    s += fmt::format("\n    ambient {}\n", fmtVec(sh["ambient"]));
    for (const Json& l : sh["lights"]) {
      std::string factors;
      for (const Json& fac : l["factors"]) {
        if (!factors.empty()) factors += "; ";
        if (sh["points"].size() > 1) factors += fmt::format("w {}: ", fmtNum(fac["weight"]));
        factors += fmt::format("n.l {}, {} {}, attenuation {}", fmtNum(fac["n_dot_l"]),
                               fac["n_dot_h"].is_null() ? "r.v" : "n.h",
                               fmtNum(fac["n_dot_h"].is_null() ? fac["r_dot_v"] : fac["n_dot_h"]),
                               fmtNum(fac["attenuation"]));
      }
      s += fmt::format("    light {} ({}): {} -> diffuse {}, specular {}\n", l["index"].get<int>(),
                       l["type"].get<std::string>(), factors, fmtVec(l["diffuse"]),
                       fmtVec(l["specular"]));
    }
    if (!sh["texture"].is_null())
      s += fmt::format("    texture {} at uv {} multiplies ambient and diffuse\n",
                       fmtVec(sh["texture"]), fmtVec(sh["uv"]));
    s += fmt::format("    colour = (ambient + sum diffuse){} + sum specular = {}, alpha {}\n",
                     sh["texture"].is_null() ? "" : " x texture",
                     fmtVec(Json::array({sh["color"][0], sh["color"][1], sh["color"][2]})),
                     fmtNum(sh["opacity"]));
    if (t["result"] == "pass") {
      if (!f["blend"].is_null())
        s += fmt::format("  blended over {} with alpha {}: src x a + dst x (1 - a) = {}, stored:\n",
                         fmtVec(f["blend"]["dst"]), fmtNum(f["blend"]["alpha"]),
                         fmtVec(f["blend"]["result"]));
      s += fmt::format("  colour buffer now {}\n", fmtVec(f["color_after"]));
    }
  }
  if (doc.contains("abuffer")) {
    const Json& ab = doc["abuffer"];
    if (ab["fragments"].empty()) {
      s += "\nA-buffer (ref:abuffer): no blended fragment here.\n";
    } else {
      s += fmt::format(
          "\nA-buffer (ref:abuffer): {} blended fragment{}, far to near (the exact order){}:\n",
          ab["fragments"].size(), ab["fragments"].size() == 1 ? "" : "s",
          ab["draw_order_matches"].get<bool>() ? ", the same as the draw order"
                                               : "; the draw order blends them differently");
      for (const Json& f : ab["fragments"])
        s += fmt::format("  {}. primitive {} ('{}', drawn {}.) window depth {}: src {} -> {}\n",
                         f["rank"].get<int>(), f["primitive"].get<int>(),
                         f["object"].get<std::string>(), f["draw_order"].get<int>() + 1,
                         fmtNum(f["window_z"]), fmtVec(f["src"]), fmtVec(f["color_after"]));
    }
  }
  const Json& fin = doc["final"];
  s += fmt::format("\nfinal: primitive {}{}, colour {}, depth {}", fmtNum(fin["id"]),
                   fin["object"].is_null()
                       ? std::string(" (background)")
                       : fmt::format(" ('{}')", fin["object"].get<std::string>()),
                   fmtVec(fin["color"]), fmtNum(fin["depth"]));
  s += fin["fragment"].is_null()
           ? " (the clear values)\n"
           : fmt::format(" (written by fragment {})\n", fmtNum(fin["fragment"]));
  const double edge = doc["edge_dist"].is_number() ? doc["edge_dist"].get<double>() : 1.0;
  s += fmt::format("uncertainty: edge_dist {} px{}, depth_gap {}\n", fmtNum(doc["edge_dist"]),
                   edge >= 1.0   ? " (capped: no edge within a pixel)"
                   : edge == 0.0 ? " (the centre lies on an edge: the tie-break rule decides)"
                   : edge < 0.1  ? " (an edge passes close: snapping may move it across)"
                                 : "",
                   doc["depth_gap"].is_null() ? std::string("none (fewer than two fragments)")
                                              : fmtNum(doc["depth_gap"]) + " steps");
  s +=
      fmt::format("  depth_slope {} steps/px, gap_slope {} steps/px, depth_reach {} steps\n",
                  fmtNum(doc["depth_slope"]), fmtNum(doc["gap_slope"]), fmtNum(doc["depth_reach"]));
  if (doc["clear_gap"].is_number())
    s += fmt::format(
        "  clear_gap {} steps (slope {}): how close the pixel came to the other side of "
        "drawn or background\n",
        fmtNum(doc["clear_gap"]), fmtNum(doc["clear_slope"]));
  if (doc["texel_alt"].is_number() && doc["texel_alt"].get<double>() > 0.0)
    s += fmt::format(
        "  texel_dist {} px: a texel boundary that close may be sampled on either side; "
        "texel_alt {} units is the colour change the other texel makes\n",
        fmtNum(doc["texel_dist"]), fmtNum(doc["texel_alt"]));
  if (doc["blend_count"].is_number() && doc["blend_count"].get<double>() > 0.0)
    s += fmt::format("  blend_count {} blended fragments, blend_gap {} steps, blend_slope {}\n",
                     fmtNum(doc["blend_count"]), fmtNum(doc["blend_gap"]),
                     fmtNum(doc["blend_slope"]));
  if (!doc["backends"].empty()) s += "backends:\n";
  for (const auto& [spec, b] : doc["backends"].items()) {
    if (b.contains("error")) {
      s += fmt::format("  {}: could not render: {}\n", spec, b["error"].get<std::string>());
      continue;
    }
    const Json& c = b["class"];
    s += fmt::format("  {}: primitive {}, colour {}, depth {}: {}", spec, fmtNum(b["id"]),
                     fmtVec(b["color"]), fmtNum(b["depth"]), c["visibility"].get<std::string>());
    if (c["visibility"] != "match" && c["visibility"] != "background")
      s += fmt::format(" (band {} px)", fmtNum(c["band_px"]));
    if (!c["depth"].is_null())
      s += fmt::format(
          "; depth {} steps (warn above {}): {}; shading {} 8-bit units (warn above "
          "{}): {}",
          fmtNum(c["depth"]["steps"]), fmtNum(c["depth"]["warn_above"]),
          c["depth"]["verdict"].get<std::string>(), fmtNum(c["shading"]["abs"]),
          fmtNum(c["shading"]["warn_above"]), c["shading"]["verdict"].get<std::string>());
    s += fmt::format("; whole image: {}\n", b["pair_status"].get<std::string>());
  }
  return s;
}

}  // namespace

int explainCommand(const ExplainArgs& args) {
  // Usage first: a bad SPEC or pixel costs nothing.
  const BackendSpec reference = parseBackendSpec(args.reference);
  if (reference.kind != BackendSpec::Kind::Reference)
    throw InputError(
        fmt::format("--reference {}: must be a reference SPEC (ref, ref:painter, "
                    "ref:abuffer, ref:subpixel=N)",
                    args.reference));
  std::vector<BackendSpec> backends;
  for (const std::string& s : args.backends) backends.push_back(parseBackendSpec(s));
  CommandLineTolerances cli;
  parseToleranceArgs(args.tolerance, cli);
  const glm::ivec2 pixel = parsePixel(args.pixel);
  const Scene scene = loadScene(args.scene);
  checkResources(scene, RendererKind::Reference, ResourceLimits::current());
  for (const std::string& spec : args.backends)
    if (parseBackendSpec(spec).kind == BackendSpec::Kind::Gl)
      checkResources(scene, RendererKind::Gl, ResourceLimits::current());
  if (pixel.x < 0 || pixel.y < 0 || pixel.x >= scene.width || pixel.y >= scene.height)
    throw InputError(fmt::format("{}: pixel {},{} is outside the {}x{} image", args.scene.string(),
                                 pixel.x, pixel.y, scene.width, scene.height));

  const std::vector<FragmentTrace> trace = tracePixel(scene, reference.reference, pixel.x, pixel.y);
  const Frame frame = renderWith(reference, scene);
  const std::size_t i = frame.index(pixel.x, pixel.y);

  Context ctx{scene, ref::sceneLighting(scene), flattenPrimitives(scene), {}, {}, {}};
  ctx.passes = drawPasses(scene, reference.reference.force_painter);
  for (std::size_t p = 0; p < ctx.passes.size(); ++p)
    for (const PrimitiveRef& prim : ctx.passes[p].primitives) ctx.pass_of[prim.id] = p;

  const DepthFormat depth_format = scene.state.depth_format;
  const ColorFormat color_format = scene.state.color_format;
  const double steps_per_unit = ref::depthStepsPerUnit(depth_format);
  glm::dvec4 buffer;  // the colour buffer as the fragments meet it
  for (int c = 0; c < 4; ++c)
    buffer[c] = ref::loadColor(ref::storeColor(scene.clear_color[c], color_format), color_format);
  const double clear_depth = ref::storedDepth(
      ref::depthKey(ref::clampDepth(scene.clear_depth), depth_format), depth_format);

  Json doc = {
      {"format", kExplainFormat},
      {"fixture", scene.name},
      {"fixture_file", args.scene.string()},
      {"image", {{"width", scene.width}, {"height", scene.height}}},
      {"pixel", {{"image", {pixel.x, pixel.y}}, {"window", {pixel.x, scene.height - 1 - pixel.y}}}},
      {"reference",
       {{"backend", reference.text},
        {"subpixel_bits", reference.reference.subpixel_bits},
        {"visibility",
         reference.reference.force_painter ? "painter" : toString(scene.state.visibility)},
        {"depth_test", scene.state.depth_test},
        {"depth_format", toString(depth_format)},
        {"color_format", toString(color_format)},
        {"blend", toString(scene.state.blend)},
        {"shading", toString(scene.state.shading)},
        {"specular_model", toString(scene.state.specular_model)},
        {"attenuation", toString(scene.state.attenuation)}}},
      {"clear", {{"color", vec(buffer)}, {"depth", clear_depth}}}};

  Json fragments = Json::array();
  std::string depth_source = "clear";
  Json final_fragment = nullptr;
  for (std::size_t k = 0; k < trace.size(); ++k) {
    const FragmentTrace& f = trace[k];
    const PrimitiveRef& prim = ctx.primitives[f.primitive - 1];
    const std::size_t pass_index = ctx.pass_of[f.primitive];
    const DrawPass& pass = ctx.passes[pass_index];
    const bool depth_write = f.depth_pass && pass.depth_write;
    Json j = {
        {"index", k + 1},
        {"primitive", f.primitive},
        {"object", scene.objects[f.object].name},
        {"object_index", f.object},
        {"triangle", prim.triangle},
        {"draw",
         {{"pass", pass_index},
          {"kind", passKind(scene, pass, reference.reference.force_painter)},
          {"depth_func", pass.depth_func == DepthFunc::Less ? "less" : "always"},
          {"depth_write", pass.depth_write},
          {"blend", pass.blend}}},
        {"barycentric", vec(f.barycentric)},
        {"depth",
         {{"window", num(f.window_z)},
          {"stored", num(f.stored_z)},
          {"steps",
           depth_format == DepthFormat::D32F
               ? Json(nullptr)
               : Json(static_cast<std::uint64_t>(std::nearbyint(f.stored_z * steps_per_unit)))},
          {"format", toString(depth_format)}}},
        {"depth_test",
         {{"func", pass.depth_func == DepthFunc::Less ? "less" : "always"},
          {"result", f.depth_pass ? "pass" : "fail"},
          {"against", num(f.depth_against)},
          {"against_source", depth_source},
          {"write", depth_write}}}};
    j["shading"] = shadingJson(ctx, f);
    // The buffer as the reference reads it back to blend (rgba8: exactly q / 255) and, in
    // color_after, as frame.exr holds it (a float per channel).
    const glm::dvec4 after = f.color_written;
    // ref:abuffer keeps a blended fragment for its pixel's sorted list ("abuffer" below).
    const bool kept = f.depth_pass && pass.blend && reference.reference.abuffer;
    if (f.depth_pass && pass.blend && !kept) {
      const glm::dvec4 src = f.shading.color;
      j["blend"] = {
          {"src", vec(src)},
          {"alpha", num(color_format == ColorFormat::RGBA8 ? ref::clampUnit(src.a) : src.a)},
          {"dst", vec(buffer)},
          {"result", vec(ref::blendSourceOver(src, buffer, color_format))}};
    } else {
      j["blend"] = nullptr;
    }
    j["written"] = f.depth_pass && !kept;
    j["color_after"] = vec(glm::dvec4(glm::vec4(after)));
    if (f.depth_pass && !kept) {
      buffer = after;
      final_fragment = k + 1;
    }
    if (depth_write) depth_source = fmt::format("fragment {}", k + 1);
    fragments.push_back(std::move(j));
  }
  doc["fragments"] = fragments;
  // The A-buffer's sorted list (ref:abuffer as --reference or among --backends): the
  // blended fragments far to near, as ref:abuffer blends them, beside the draw order above.
  const bool show_abuffer = reference.reference.abuffer ||
                            std::any_of(backends.begin(), backends.end(), [](const BackendSpec& b) {
                              return b.kind == BackendSpec::Kind::Reference && b.reference.abuffer;
                            });
  if (show_abuffer) {
    ReferenceOptions opts = reference.reference;
    opts.abuffer = true;
    Json list = Json::array();
    std::uint32_t prev_order = 0;
    bool in_order = true;
    for (const SortedFragment& f : abufferPixel(scene, opts, pixel.x, pixel.y)) {
      if (!list.empty() && f.draw_order < prev_order) in_order = false;
      prev_order = f.draw_order;
      list.push_back({{"rank", list.size() + 1},
                      {"primitive", f.primitive},
                      {"object", scene.objects[ctx.primitives[f.primitive - 1].object].name},
                      {"draw_order", f.draw_order},
                      {"window_z", num(f.window_z)},
                      {"src", vec(f.color)},
                      {"color_after", vec(glm::dvec4(glm::vec4(f.color_after)))}});
    }
    doc["abuffer"] = {{"fragments", list}, {"draw_order_matches", in_order}};
  }

  const std::uint32_t final_id = frame.id[i];
  doc["final"] = {
      {"id", final_id},
      {"object", final_id == 0 ? Json(nullptr)
                               : Json(scene.objects[ctx.primitives[final_id - 1].object].name)},
      {"color", Json::array({num(frame.color[4 * i]), num(frame.color[4 * i + 1]),
                             num(frame.color[4 * i + 2]), num(frame.color[4 * i + 3])})},
      {"depth", num(frame.depth[i])},
      {"fragment", final_fragment}};
  // Every uncertainty channel at the pixel, by its frame.exr name (edge_dist, depth_gap,
  // depth_slope, ...).
  for (int c = 0; c < kUncertaintyChannels; ++c)
    doc[kUncertaintyChannelInfo[c].name] = num((*frame.uncertainty()[c])[i]);

  // Each backend renders its own frame (GL in a child process) and is compared with the
  // reference frame as `compare` would.
  Json out_backends = Json::object();
  bool backend_failed = false;
  if (!backends.empty()) {
    ScratchDir scratch("explain");
    for (std::size_t b = 0; b < backends.size(); ++b) {
      try {
        const Frame other = renderBackend(backends[b], scene, fs::absolute(args.scene),
                                          scratch.path() / fmt::format("backend{}", b));
        checkSameSize(frame, other, args.scene, backends[b].text);
        out_backends[backends[b].text] = backendJson(backends[b], frame, other, scene, cli, i);
      } catch (const BackendError& e) {
        backend_failed = true;
        out_backends[backends[b].text] = {{"backend", backends[b].text}, {"error", e.what()}};
      }
    }
  }
  doc["backends"] = out_backends;

  if (args.json) {
    std::cout << doc.dump(2) << '\n';
  } else {
    std::cout << story(doc);
  }
  return backend_failed ? kExitBackend : kExitPass;
}

}  // namespace rc
