// Pixel history and its story: see pixel_history.h.
#include "debug/pixel_history.h"

#include "reference/multipass.h"
#include "reference/shadow.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "compare/compare.h"
#include "fixtures/errors.h"
#include "fixtures/scene_logic.h"
#include "reference/fragment_ops.h"
#include "reference/shading.h"

namespace rc {
namespace {

using Json = nlohmann::ordered_json;

Json num(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }
Json vec(const glm::dvec3& v) { return Json::array({num(v.x), num(v.y), num(v.z)}); }
Json vec(const glm::dvec4& v) { return Json::array({num(v.x), num(v.y), num(v.z), num(v.w)}); }

const char* lightType(const Light& l) {
  return l.type == LightType::Point ? "point" : "directional";
}

// One light's factors at one shaded point, as the reference's lighting code recorded them.
Json factorsJson(const LightFactors& f, double weight) {
  return {{"weight", weight},
          {"distance", num(f.distance)},
          {"attenuation", num(f.attenuation)},
          {"n_dot_l", num(f.n_dot_l)},
          {"n_dot_h", num(f.n_dot_h)},
          {"r_dot_v", num(f.r_dot_v)},
          {"specular_power", num(f.specular_power)},
          {"contributes", f.contributes}};
}

// The shadow lookup of a light at a Phong fragment (null when the material's lookup does
// not read the light's map): where it lands in the map pass's target, the depth stored
// there and the range another driver's may take, the comparison and its result.
Json shadowJson(const Material& material, const Light& light, const ShadingTerms& terms) {
  if (!material.shadow || material.shadow->data == nullptr || terms.points.size() != 1 ||
      light.shadow_map.empty() || light.shadow_map != material.shadow->map)
    return nullptr;
  const ShadowLookup& lookup = *material.shadow;
  const ShadowMapData& map = *lookup.data;
  const glm::dvec3 p = terms.points.front().position;
  const ref::ShadowCoord c = ref::shadowCoord(lookup, p);
  Json j = {{"map", lookup.map},
            {"filter", toString(lookup.filter)},
            {"compare", toString(lookup.compare)},
            {"bias", num(lookup.bias)},
            {"in_front", c.in_front},
            {"result", num(ref::shadowFactor(lookup, p))}};
  if (!c.in_front) return j;
  const bool linear = lookup.filter == TextureFilter::Linear;
  // The texel the lookup reads (linear: its footprint's lower-left), as shadowRange() finds it.
  const ref::ShadowRange read = ref::shadowRange(lookup, p, 0.0, 0.0, 0.0);
  const int i = read.i;
  const int t = read.j;
  j["coord"] = {num(c.s), num(c.t), num(c.r)};
  Json texels = Json::array();
  for (int dt = 0; dt <= (linear ? 1 : 0); ++dt) {
    for (int ds = 0; ds <= (linear ? 1 : 0); ++ds) {
      const int x = std::min(i + ds, map.width - 1);
      const int y = std::min(t + dt, map.height - 1);
      const std::size_t k = static_cast<std::size_t>(y) * map.width + x;
      texels.push_back(
          {{"texel", {x, y}},
           {"image", {x, map.height - 1 - y}},  // the map's frame.exr pixel (top-left origin)
           {"stored", num(map.depth[k])},
           {"allowed", map.lo.empty() ? Json(nullptr) : Json{num(map.lo[k]), num(map.hi[k])}}});
    }
  }
  j["texels"] = texels;
  return j;
}

// The shading block of one fragment, all from the trace: the points the lighting model
// was evaluated at (with the per-point sums the colour is built from), the terms, and
// each light's factors at each point.
Json shadingJson(const Scene& scene, const FragmentTrace& f) {
  const Material& material = scene.materials[scene.objects[f.object].material];
  const ShadingTerms& terms = f.shading;
  const char* at = scene.state.shading == Shading::Flat      ? "centroid"
                   : scene.state.shading == Shading::Gouraud ? "vertices"
                                                             : "fragment";
  Json j = {{"model", toString(scene.state.shading)},
            {"specular_model", toString(scene.state.specular_model)},
            {"evaluated_at", at}};
  Json pts = Json::array();
  for (const ShadedPoint& p : terms.points) {
    pts.push_back({{"weight", p.weight},
                   {"position", vec(p.position)},
                   {"normal", vec(p.normal)},
                   {"ambient_diffuse", vec(p.ambient_diffuse)},
                   {"specular", vec(p.specular)}});
  }
  j["points"] = pts;
  // Level-of-detail sampling: what chose the level(s), and the interval a conforming driver
  // may use (docs/tolerances.md section 9); null otherwise.
  const ShadingTerms::Lod& lod = terms.lod;
  j["texture_lod"] =
      lod.used ? Json{{"derivatives",
                       {num(lod.d_dx.x), num(lod.d_dx.y), num(lod.d_dy.x), num(lod.d_dy.y)}},
                      {"rho", num(lod.rho)},
                      {"lambda", num(lod.lambda)},
                      {"magnified", lod.magnified},
                      {"levels", {lod.level0, lod.level1}},
                      {"weight", num(lod.weight)},
                      {"lambda_allowed", {num(lod.lambda_lo), num(lod.lambda_hi)}}}
               : Json(nullptr);
  j["ambient"] = vec(terms.ambient);
  Json lights = Json::array();
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& light = scene.lights[i];
    Json factors = Json::array();
    for (const ShadedPoint& p : terms.points)
      factors.push_back(factorsJson(i < p.lights.size() ? p.lights[i] : LightFactors{}, p.weight));
    const LightTerms t = i < terms.lights.size() ? terms.lights[i] : LightTerms{};
    lights.push_back({{"index", i},
                      {"type", lightType(light)},
                      {"color", vec(light.color)},
                      {"intensity", num(light.intensity)},
                      {"diffuse", vec(t.diffuse)},
                      {"specular", vec(t.specular)},
                      {"factors", factors},
                      {"shadow", shadowJson(material, light, terms)}});
  }
  j["lights"] = lights;
  if (material.texture) {
    j["texture"] = vec(terms.texture);
    j["uv"] = Json::array({num(terms.uv.x), num(terms.uv.y)});
  } else {
    j["texture"] = nullptr;
    j["uv"] = nullptr;
  }
  j["opacity"] = num(material.opacity);
  j["color"] = vec(terms.color);
  return j;
}

std::string passKind(const Scene& scene, const DrawPass& pass, bool force_painter) {
  if (pass.blend) return "transparent";
  if (force_painter || scene.state.visibility == Visibility::Painter) return "painter";
  return "opaque";
}

Json pixelColor(const Frame& frame, std::size_t i) {
  return Json::array({num(frame.color[4 * i]), num(frame.color[4 * i + 1]),
                      num(frame.color[4 * i + 2]), num(frame.color[4 * i + 3])});
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

// A shadowed light's lookup (shading.lights[].shadow), its texels one line each.
std::string shadowStory(const Json& lookup) {
  if (!lookup["in_front"].get<bool>())
    return fmt::format("      shadow map {}: behind its camera, not shadowed\n",
                       lookup["map"].get<std::string>());
  std::string s = fmt::format("      shadow map {} ({} {}, bias {}) at (s, t, r) {}: result {}\n",
                              lookup["map"].get<std::string>(), lookup["filter"].get<std::string>(),
                              lookup["compare"].get<std::string>(), fmtNum(lookup["bias"]),
                              fmtVec(lookup["coord"]), fmtNum(lookup["result"]));
  for (const Json& texel : lookup["texels"])
    s +=
        fmt::format("        texel {} (map pixel {}): stored {}, another driver's in {}\n",
                    fmtVec(texel["texel"]), fmtVec(texel["image"]), fmtNum(texel["stored"]),
                    texel["allowed"].is_null() ? std::string("(exact)") : fmtVec(texel["allowed"]));
  return s;
}

// "triangle", "segment" or "point", by what the fragment's primitive is.
std::string primitiveNoun(const Json& f) {
  const std::string kind = f.value("primitive_kind", std::string("triangles"));
  if (kind == "points") return "point";
  if (kind == "triangles") return "triangle";
  return "segment";
}

// How a line or point fragment came about: the rule, the parameter, the margin.
std::string lineStory(const Json& l) {
  const double margin = l["margin"].is_null() ? 0.0 : l["margin"].get<double>();
  const std::string decided =
      margin > 0.0 ? fmt::format("its centre is {} px from where the rule decides the other way",
                                 fmtNum(l["margin"]))
                   : "a line end, a tie or a clipped point: GL leaves this pixel to the driver";
  if (l["kind"] == "point") {
    return fmt::format(
        "  {}point at window {}, size {}: the pixels whose centres lie in the square of that "
        "side; {}\n",
        l["polygon_edge"].get<bool>() ? "a polygon vertex drawn as a " : "", fmtVec(l["a"]),
        fmtNum(l["size"]), decided);
  }
  const std::string rule = l["rule"] == "column"
                               ? fmt::format("GL's column rule for width {}", fmtNum(l["size"]))
                               : std::string("GL's diamond-exit rule");
  return fmt::format(
      "  {}segment from window {} to {} ({}); the centre projects to t = {} along it (the "
      "parameter its depth and attributes take); {}\n",
      l["polygon_edge"].get<bool>() ? "polygon edge (polygon mode line): " : "", fmtVec(l["a"]),
      fmtVec(l["b"]), rule, fmtNum(l["t"]), decided);
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
        "\nfragment {}: primitive {}, {} {} of '{}' ({} pass {}), barycentric "
        "{}\n",
        f["index"].get<int>(), f["primitive"].get<int>(), primitiveNoun(f),
        f["triangle"].get<int>(), f["object"].get<std::string>(),
        f["draw"]["kind"].get<std::string>(), f["draw"]["pass"].get<int>(),
        fmtVec(f["barycentric"]));
    if (f.contains("line")) s += lineStory(f["line"]);
    const Json& d = f["depth"];
    s += fmt::format(
        "  window depth {}, stored as {}{}\n", fmtNum(d["window"]), fmtNum(d["stored"]),
        d["steps"].is_null()
            ? ""
            : fmt::format(" ({} steps of {})", fmtNum(d["steps"]), d["format"].get<std::string>()));
    const Json& t = f["depth_test"];
    // The fragment operations before the depth test, when the scene has them.
    if (f.contains("ops")) {
      const Json& ops = f["ops"];
      if (!ops["scissor"].is_null())
        s += fmt::format("  scissor test: {}\n", ops["scissor"].get<std::string>());
      if (ops["scissor"] == "fail") {
        s += "  outside the scissor box: discarded, nothing written\n";
        continue;
      }
      if (!ops["polygon_offset"].is_null())
        s += fmt::format("  polygon offset {} added to the window depth\n",
                         fmtNum(ops["polygon_offset"]));
      if (!ops["stencil"].is_null()) {
        const Json& st = ops["stencil"];
        s += fmt::format("  stencil test against {}: {}, stencil now {}\n", fmtNum(st["before"]),
                         st["result"].get<std::string>(), fmtNum(st["after"]));
        if (st["result"] == "fail") {
          s += "  failed the stencil test: discarded, nothing else written\n";
          continue;
        }
      }
    }
    const std::string against = t["against_source"] == "clear"
                                    ? fmt::format("the clear depth {}", fmtNum(t["against"]))
                                    : fmt::format("{} (stored by {})", fmtNum(t["against"]),
                                                  t["against_source"].get<std::string>());
    const std::string func = t["func"].get<std::string>();
    if (func == "always") {
      s += "  no depth test (ALWAYS)";
    } else if (func != "less") {
      s += fmt::format("  {} the depth test ({}) against {}: {} vs {}",
                       t["result"] == "pass" ? "passed" : "failed", func, against,
                       fmtNum(d["stored"]), fmtNum(t["against"]));
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
      if (l.contains("shadow") && !l["shadow"].is_null()) s += shadowStory(l["shadow"]);
    }
    if (!sh["texture"].is_null())
      s += fmt::format("    texture {} at uv {} multiplies ambient and diffuse\n",
                       fmtVec(sh["texture"]), fmtVec(sh["uv"]));
    if (sh.contains("texture_lod") && !sh["texture_lod"].is_null()) {
      const Json& l = sh["texture_lod"];
      s += fmt::format(
          "    level of detail: derivatives {} texels/px, rho {}, lambda {} ({}), levels {} "
          "weight {}; a conforming lambda lies in {}\n",
          fmtVec(l["derivatives"]), fmtNum(l["rho"]), fmtNum(l["lambda"]),
          l["magnified"].get<bool>() ? "magnified" : "minified", fmtVec(l["levels"]),
          fmtNum(l["weight"]), fmtVec(l["lambda_allowed"]));
    }
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
  if (doc["shade_reach"].is_number() && doc["shade_reach"].get<double>() > 0.0)
    s += fmt::format(
        "  shade_reach {} units/px: how much the colour moves per px its vertices move "
        "(interpolated colours; the slope band times it is allowed)\n",
        fmtNum(doc["shade_reach"]));
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
    if (c.contains("shading") && c["shading"].is_object() &&
        c["shading"]["allowance_rgba"].is_array())
      s += fmt::format(
          "    shading per channel (R, G, B, A): actual - reference {} 8-bit units, "
          "allowances {}; a channel warns above its allowance + {} and fails above its "
          "allowance + {}\n",
          fmtVec(c["shading"]["delta_rgba"]), fmtVec(c["shading"]["allowance_rgba"]),
          fmtNum(c["shading"]["base_warn"]), fmtNum(c["shading"]["base_fail"]));
    if (b.contains("shadow_texels")) {
      for (const Json& t : b["shadow_texels"])
        s += fmt::format(
            "    shadow map {} texel {} (light {}): the driver stored {}, the reference {}\n",
            t["map"].get<std::string>(), fmtVec(t["texel"]), fmtNum(t["light"]),
            fmtNum(t["driver"]), fmtNum(t["reference"]));
    }
  }
  return s;
}

}  // namespace

Json pixelHistory(const Scene& multi, const PixelQuery& query, const Frame& frame) {
  // A multi-pass fixture: the frame pass, its targets drawn (the history is the frame's).
  ref::PassOutputs outputs;
  if (!multi.passes.empty()) outputs = ref::renderPasses(multi, query.options);
  const Scene& scene = multi.passes.empty() ? multi : outputs.frame_scene;
  const glm::ivec2 pixel(query.x, query.y);
  if (pixel.x < 0 || pixel.y < 0 || pixel.x >= scene.width || pixel.y >= scene.height)
    throw InputError(fmt::format("{}: pixel {},{} is outside the {}x{} image", query.fixture_file,
                                 pixel.x, pixel.y, scene.width, scene.height));
  const ReferenceOptions& options = query.options;
  // The frame pass with its targets bound above: its passes are not drawn again.
  const std::vector<FragmentTrace> trace = tracePixel(scene, options, pixel.x, pixel.y);
  const std::size_t i = frame.index(pixel.x, pixel.y);
  const std::vector<PrimitiveRef> primitives = flattenPrimitives(scene);  // by id - 1
  const std::vector<DrawPass> passes = drawPasses(scene, options.force_painter);
  std::map<std::uint32_t, std::size_t> pass_of;  // id -> draw pass
  for (std::size_t p = 0; p < passes.size(); ++p)
    for (const PrimitiveRef& prim : passes[p].primitives) pass_of[prim.id] = p;

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
      {"fixture_file", query.fixture_file},
      {"image", {{"width", scene.width}, {"height", scene.height}}},
      {"pixel", {{"image", {pixel.x, pixel.y}}, {"window", {pixel.x, scene.height - 1 - pixel.y}}}},
      {"reference",
       {{"backend", query.reference_spec},
        {"subpixel_bits", options.subpixel_bits},
        {"visibility", options.force_painter ? "painter" : toString(scene.state.visibility)},
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
    const PrimitiveRef& prim = primitives[f.primitive - 1];
    const std::size_t pass_index = pass_of[f.primitive];
    const DrawPass& pass = passes[pass_index];
    const bool depth_write = f.depth_pass && pass.depth_write;
    Json j = {
        {"index", k + 1},
        {"primitive", f.primitive},
        {"object", scene.objects[f.object].name},
        {"object_index", f.object},
        {"triangle", prim.triangle},
        {"primitive_kind", toString(scene.objects[prim.object].primitive)},
        {"draw",
         {{"pass", pass_index},
          {"kind", passKind(scene, pass, options.force_painter)},
          {"depth_func", toString(pass.depth_func)},
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
         {{"func", toString(pass.depth_func)},
          {"result", f.depth_pass ? "pass" : "fail"},
          {"against", num(f.depth_against)},
          {"against_source", depth_source},
          {"write", depth_write}}}};
    j["shading"] = shadingJson(scene, f);
    if (f.line.kind != LineTrace::Kind::None) {
      const bool segment = f.line.kind == LineTrace::Kind::Segment;
      j["line"] = {{"kind", segment ? "segment" : "point"},
                   {"polygon_edge", f.line.polygon_edge},
                   {"a", {num(f.line.a.x), num(f.line.a.y)}},
                   {"b", segment ? Json{num(f.line.b.x), num(f.line.b.y)} : Json(nullptr)},
                   {"size", num(f.line.size)},
                   {"rule", segment ? (f.line.size > 1.0 ? "column" : "diamond-exit") : "square"},
                   {"t", segment ? num(f.line.t) : Json(nullptr)},
                   {"margin", num(f.line.margin)}};
    }
    // The fragment operations before the depth test, in GL's order (null: not set).
    const FragmentOps& ops = pass.ops;
    Json stencil = nullptr;
    if (f.stencil_before >= 0) {
      stencil = {{"before", f.stencil_before},
                 {"result", f.stencil_pass ? "pass" : "fail"},
                 {"after", f.stencil_after}};
    }
    j["ops"] = {{"scissor", ops.scissor ? Json(f.scissor_pass ? "pass" : "fail") : Json(nullptr)},
                {"stencil", stencil},
                {"depth_range", {num(ops.depth_range.x), num(ops.depth_range.y)}},
                {"polygon_offset", ops.polygon_offset ? num(f.offset) : Json(nullptr)},
                {"color_mask", ops.color_mask}};
    // The buffer as the reference reads it back to blend (rgba8: exactly q / 255) and, in
    // color_after, as frame.exr holds it (a float per channel).
    const glm::dvec4 after = f.color_written;
    // ref:abuffer keeps a blended fragment for its pixel's sorted list ("abuffer" below).
    const bool kept = f.depth_pass && pass.blend && options.abuffer;
    if (f.depth_pass && pass.blend && !kept) {
      const glm::dvec4 src = f.shading.color;
      j["blend"] = {
          {"src", vec(src)},
          {"alpha", num(color_format == ColorFormat::RGBA8 ? ref::clampUnit(src.a) : src.a)},
          {"dst", vec(buffer)},
          {"result", vec(pass.blend_function ? ref::blendWithFunction(pass.ops.blend_function, src,
                                                                      buffer, color_format)
                                             : ref::blendSourceOver(src, buffer, color_format))}};
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
  if (options.abuffer || query.abuffer) {
    ReferenceOptions opts = options;
    opts.abuffer = true;
    Json list = Json::array();
    std::uint32_t prev_order = 0;
    bool in_order = true;
    for (const SortedFragment& f : abufferPixel(scene, opts, pixel.x, pixel.y)) {
      if (!list.empty() && f.draw_order < prev_order) in_order = false;
      prev_order = f.draw_order;
      list.push_back({{"rank", list.size() + 1},
                      {"primitive", f.primitive},
                      {"object", scene.objects[primitives[f.primitive - 1].object].name},
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
      {"object",
       final_id == 0 ? Json(nullptr) : Json(scene.objects[primitives[final_id - 1].object].name)},
      {"color", pixelColor(frame, i)},
      {"depth", num(frame.depth[i])},
      {"fragment", final_fragment}};
  // Every uncertainty channel at the pixel, by its frame.exr name (edge_dist, depth_gap,
  // depth_slope, ...).
  for (int c = 0; c < kUncertaintyChannels; ++c)
    doc[kUncertaintyChannelInfo[c].name] = num((*frame.uncertainty()[c])[i]);
  doc["backends"] = Json::object();
  return doc;
}

Json backendPixel(const std::string& spec, const Frame& reference, const Frame& frame,
                  const Tolerances& tolerances, std::size_t i) {
  Json j = {{"backend", spec}};
  if (frame.meta.contains("renderer")) j["renderer"] = frame.meta["renderer"];
  j["subpixel_bits"] =
      frame.meta.contains("subpixel_bits") ? Json(frame.meta["subpixel_bits"]) : Json(nullptr);
  j["id"] = frame.id[i];
  j["color"] = pixelColor(frame, i);
  j["depth"] = num(frame.depth[i]);

  ClassMaps maps;
  maps.describe_pixel = i;
  const PairResult r = compareFrames(reference, frame, reference, tolerances, &maps);
  const PixelClass cls = maps.pixel_class[i];
  const PixelClassInfo& info = pixelClassInfo(cls);
  Json c = {{"visibility", info.key},
            {"ambiguous", info.ambiguous},
            {"band_px", num(r.visibility.band_px)}};
  if (cls == PixelClass::Match) {
    // The comparator's own thresholds for this pixel (its allowance on top of warn and
    // fail) and its verdict on them.
    const double steps = maps.depth_steps[i];
    const Thresholds depth = depthThresholdsAt(maps, i, tolerances);
    c["depth"] = {{"steps", num(steps)},
                  {"warn_above", num(depth.warn)},
                  {"fail_above", num(depth.fail)},
                  {"verdict", toString(depth.verdict(steps))}};
    const double shading = maps.shading_abs[i];
    const Thresholds held = shadingThresholdsAt(maps, i, tolerances);
    Json delta = Json::array();
    for (int k = 0; k < 4; ++k)
      delta.push_back(num((static_cast<double>(frame.color[4 * i + k]) -
                           static_cast<double>(reference.color[4 * i + k])) *
                          255.0));
    c["shading"] = {{"abs", num(shading)},
                    {"delta_rgba", delta},
                    {"warn_above", num(held.warn)},
                    {"fail_above", num(held.fail)},
                    {"verdict", toString(held.verdict(shading))}};
    // Each channel's own allowance (a channel warns above allowance + warn): computed by
    // the comparison only where the largest channel error is over warn, null elsewhere.
    if (!std::isnan(maps.describe_allowances[0])) {
      Json allowances = Json::array();
      for (const double a : maps.describe_allowances) allowances.push_back(num(a));
      c["shading"]["allowance_rgba"] = allowances;
      c["shading"]["base_warn"] = num(tolerances.shading.warn);
      c["shading"]["base_fail"] = num(tolerances.shading.fail);
    } else {
      c["shading"]["allowance_rgba"] = nullptr;
    }
  } else {
    c["depth"] = nullptr;
    c["shading"] = nullptr;
  }
  j["class"] = c;
  j["pair_status"] = toString(r.status);
  return j;
}

Json backendShadowTexels(const Json& doc, const Frame& frame) {
  Json out = Json::array();
  const Json& final_fragment = doc.at("final").at("fragment");
  if (final_fragment.is_null()) return out;
  const Json& f = doc.at("fragments").at(final_fragment.get<std::size_t>() - 1);
  for (const Json& light : f.at("shading").at("lights")) {
    const Json& sh = light.at("shadow");
    if (sh.is_null() || !sh.contains("texels")) continue;
    const Frame* map = nullptr;
    for (const Frame& pass : frame.passes)
      if (pass.meta.contains("pass") && pass.meta["pass"].value("target", "") == sh["map"])
        map = &pass;
    for (const Json& t : sh["texels"]) {
      Json j = {{"light", light["index"]},
                {"map", sh["map"]},
                {"texel", t["texel"]},
                {"reference", t["stored"]},
                {"driver", nullptr}};
      if (map != nullptr) {
        const int x = t["image"][0].get<int>();
        const int y = t["image"][1].get<int>();
        if (x >= 0 && y >= 0 && x < map->width && y < map->height)
          j["driver"] = num(map->depth[map->index(x, y)]);
      }
      out.push_back(j);
    }
  }
  return out;
}

std::string pixelStory(const Json& doc) { return story(doc); }

}  // namespace rc
