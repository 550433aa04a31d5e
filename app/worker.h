// The hidden `rastercheck worker --backend SPEC` mode that `run` keeps one or more of per
// backend (app/worker_pool.h), and the wire protocol between the two. A worker loads its
// backend once (GL driver and context on the first render) and renders fixture after
// fixture:
//   request, parent -> worker on stdin: one JSON line {"id": N, "fixture": "/abs/f.json"},
//   with "fault": "SETTING" (test-only) to render this fixture alone with that
//   RASTERCHECK_GL_FAULT setting (gl_backend/gl_testing.h), and "pass_frames": true to send
//   a multi-pass scene's pass frames with its frame
//   reply, worker -> parent on fd 3: a ReplyHeader, then `length` bytes: the frame as
//   encodeFrame() gives it (kind Frame), or a one-line message (the other kinds).
// Its stdout and stderr (driver chatter, warnings) go to a log file the parent reads.
#pragma once

#include <cstdint>

namespace rc::worker {

inline constexpr int kReplyFd = 3;
inline constexpr char kReplyTag[4] = {'R', 'C', 'W', '1'};

enum class ReplyKind : std::uint32_t { Frame = 0, InputError = 1, BackendError = 2 };

struct ReplyHeader {
  char tag[4];
  ReplyKind kind;
  std::uint64_t id;
  std::uint64_t length;
};
static_assert(sizeof(ReplyHeader) == 24);

}  // namespace rc::worker
