// See worker.h: the worker's request loop.
#include "app/worker.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>

#include <nlohmann/json.hpp>

#include "app/backends.h"
#include "app/commands.h"
#include "fixtures/big_buffer.h"
#include "fixtures/errors.h"
#include "fixtures/frame_stream.h"
#include "fixtures/loader.h"
#include "gl_backend/gl_testing.h"

namespace rc::worker {
namespace {

bool writeAll(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

bool reply(ReplyKind kind, std::uint64_t id, const std::string& payload) {
  ReplyHeader h{};
  std::memcpy(h.tag, kReplyTag, sizeof h.tag);
  h.kind = kind;
  h.id = id;
  h.length = payload.size();
  return writeAll(kReplyFd, reinterpret_cast<const char*>(&h), sizeof h) &&
         writeAll(kReplyFd, payload.data(), payload.size());
}

}  // namespace

}  // namespace rc::worker

namespace rc {

namespace {
constexpr int kReferenceNice = 5;
}  // namespace

// Serves requests until stdin ends: exit 0, or 3 when the reply pipe broke. A fixture or
// render that fails is a reply, not an exit.
int workerCommand(const std::string& spec) {
  using namespace worker;
  const BackendSpec backend = parseBackendSpec(spec);
  // The reference's worker yields to the GL workers: in every run measured the reference had
  // the least work (gen200: 6 ms a render against llvmpipe's 7, softpipe's 26 and zink's 28),
  // so the drivers' workers are the run's critical path and the reference fills the time
  // they leave. Niceness only orders the workers when the cores are short; nice 5 still gives
  // it a quarter of a core against a busy one (the watchdog's --timeout stays far off).
  // gen200 x llvmpipe: 1.19 -> 1.10 s a run (docs/performance.md).
  if (backend.kind == BackendSpec::Kind::Reference) (void)::nice(kReferenceNice);
  keepFreedMemory();  // one fixture's frames after another (fixtures/big_buffer.h)
  std::string line;
  while (std::getline(std::cin, line)) {
    const nlohmann::json request = nlohmann::json::parse(line, nullptr, false);
    if (request.is_discarded() || !request.contains("id") || !request.contains("fixture")) {
      std::cerr << "rastercheck worker: malformed request: " << line << '\n';
      return kExitInput;
    }
    const auto id = request["id"].get<std::uint64_t>();
    ReplyKind kind = ReplyKind::Frame;
    std::string payload;
    try {
      const Scene scene = loadScene(request["fixture"].get<std::string>());
      // A test-only fault for this render alone (the mutation study): set in the hooks,
      // which take precedence over RASTERCHECK_GL_FAULT, and cleared after the render.
      struct FaultScope {
        explicit FaultScope(const nlohmann::json& r) {
          if (r.contains("fault") && r["fault"].is_string())
            gl::testing::hooks().faults = gl::testing::parseFaults(r["fault"].get<std::string>());
        }
        ~FaultScope() { gl::testing::hooks().faults = {}; }
        FaultScope(const FaultScope&) = delete;
        FaultScope& operator=(const FaultScope&) = delete;
      } fault(request);
      // A multi-pass scene's pass frames only when asked (`explain`): `run` compares the
      // frame pass, and the reference's pass frames (shadow maps and render targets, with
      // their uncertainty channels) were megabytes a render through the pipe; GL's
      // read-back of them ~1.7 ms a multi-pass render on llvmpipe.
      const auto asked = request.find("pass_frames");
      const bool pass_frames = asked != request.end() && asked->is_boolean() && asked->get<bool>();
      payload = encodeFrame(renderWith(backend, scene, pass_frames));
    } catch (const InputError& e) {
      kind = ReplyKind::InputError;
      payload = e.what();
    } catch (const BackendError& e) {
      kind = ReplyKind::BackendError;
      payload = e.what();
    } catch (const std::exception& e) {
      kind = ReplyKind::BackendError;
      payload = std::string("internal error: ") + e.what();
    }
    std::fflush(nullptr);  // the log shows what this render printed before its reply
    if (!reply(kind, id, payload)) return kExitBackend;
  }
  return kExitPass;
}

}  // namespace rc
