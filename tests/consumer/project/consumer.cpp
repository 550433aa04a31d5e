// A program outside rastercheck built against its installed package: one fixture of the
// installed catalog, rendered by the reference and by an OpenGL driver, compared in this
// process, and the verdict printed. Exit status: 0 pass or warn, 1 fail, 2 anything else.
#include <cstdio>
#include <exception>
#include <string>

#include <rastercheck/compare/compare.h>
#include <rastercheck/fixtures/loader.h>
#include <rastercheck/gl_backend/gl_backend.h>
#include <rastercheck/reference/reference_renderer.h>

int main(int argc, char** argv) {
  const std::string fixture = argc > 1 ? argv[1] : CATALOG "/shading/blinn_phong_sphere.json";
  const std::string backend = argc > 2 ? argv[2] : "gl:egl:llvmpipe";
  try {
    const rc::Scene scene = rc::loadScene(fixture);
    const rc::PairResult r = rc::compareFrames(rc::renderReference(scene),
                                               rc::renderGl(scene, rc::parseGlSpec(backend)));
    std::printf("%s ref vs %s: %s (visibility %s, depth %s, shading %s)\n", scene.name.c_str(),
                backend.c_str(), rc::toString(r.status), rc::toString(r.visibility.status),
                rc::toString(r.depth.status), rc::toString(r.shading.status));
    return r.status == rc::Status::Fail ? 1 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 2;
  }
}
