// See cli.h. Options are declared as data with help text (idiff style); every failure
// ends as one line on stderr and an exit code from fixtures/errors.h.
#include "app/cli.h"

#include <iostream>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "app/version.h"
#include "fixtures/errors.h"

namespace rc {

int runCli(int argc, char** argv) {
  CLI::App app{
      "rastercheck: renders fixtures with a scalar CPU reference and with OpenGL drivers, and "
      "says per pixel where and why they disagree.\n"
      "Exit codes: 0 pass (warnings allowed), 1 a comparison failed, 2 bad input or usage, "
      "3 a backend could not run."};
  app.set_version_flag("--version", std::string("rastercheck ") + kVersion);
  app.require_subcommand(1);

  RenderArgs render;
  CLI::App* render_cmd = app.add_subcommand("render", "Render one fixture with one backend");
  render_cmd->add_option("scene", render.scene, "Fixture file (JSON)")->required();
  render_cmd
      ->add_option("--backend,-b", render.backend,
                   "ref, ref:painter, ref:subpixel=N, gl, gl:egl[:llvmpipe|:softpipe], "
                   "gl:osmesa[:llvmpipe|:softpipe], gl:egl-device[:N]")
      ->capture_default_str();
  render_cmd->add_option("--out,-o", render.out, "Output folder (frame.exr, color.png, frame.json)")
      ->required();

  ListArgs list;
  CLI::App* list_cmd = app.add_subcommand("list", "List fixtures: name, tags, description");
  list_cmd->add_option("paths", list.paths, "Fixture files or folders (default: the catalog)");
  list_cmd->add_flag("--json", list.json, "Print JSON");
  list_cmd->add_flag("--markdown", list.markdown, "Print a Markdown table");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help/version or the parse error
    return code == 0 ? kExitPass : kExitInput;
  }

  try {
    if (*render_cmd) return renderCommand(render);
    if (*list_cmd) return listCommand(list);
  } catch (const InputError& e) {
    std::cerr << "rastercheck: error: " << e.what() << '\n';
    return kExitInput;
  } catch (const BackendError& e) {
    std::cerr << "rastercheck: backend error: " << e.what() << '\n';
    return kExitBackend;
  } catch (const std::exception& e) {
    std::cerr << "rastercheck: internal error: " << e.what() << '\n';
    return kExitBackend;
  }
  return kExitInput;
}

}  // namespace rc
