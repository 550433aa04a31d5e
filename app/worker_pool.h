// Long-lived render workers for `run`, as deqp-runner keeps them: each worker is this
// program in its hidden `worker` mode (app/worker.h) with one backend loaded once, and
// renders fixture after fixture; frames come back through a pipe, not through files. A
// worker that crashes, exits, or overruns the per-fixture watchdog costs the render it
// was doing (an outcome naming the signal or the timeout); it is killed if need be, and
// the next render of its backend starts a new one.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fixtures/frame.h"

namespace rc {

struct RenderRequest {
  std::filesystem::path fixture;  // absolute
  std::string spec;
  // Test-only: a RASTERCHECK_GL_FAULT setting for this render alone (gl_backend/gl_testing.h),
  // so that the mutation study's faulted renders share the clean renders' workers.
  std::string fault;
  // Rendered by a worker started for this render alone and ended after it (`run --retries`:
  // nothing the driver kept from earlier fixtures can reach it).
  bool fresh = false;
  // A multi-pass scene's pass frames sent too (frame.passes: `explain` reads the driver's
  // shadow maps there); without, the frame pass alone.
  bool pass_frames = false;
};

struct RenderOutcome {
  bool ok = false;
  Frame frame;               // when ok
  std::string error;         // when not ok: one line, the backend's or how the worker died
  bool input_error = false;  // the worker judged the fixture bad input (exit 2 alone)
  std::string log;           // what the worker printed while rendering this one
};

class WorkerPool {
 public:
  struct Options {
    int max_busy = 1;               // renders at a time, over all backends
    double timeout_seconds = 0.0;   // per render; 0: no watchdog
    std::filesystem::path log_dir;  // where worker logs go (created if needed)
    // The program started in worker mode: empty for this one (`run`); a test names
    // rastercheck.
    std::filesystem::path program;
    // NAME=VALUE entries added to the workers' environment (e.g. the mutation study's
    // TMPDIR under its campaign folder).
    std::vector<std::string> environment;
    // Workers of one backend at a time; 0: workersFor()'s choice (one for llvmpipe and zink,
    // which JIT-compile their variants in each process; else a second and further ones only
    // while the backend's queued renders are worth more than starting one).
    int max_workers_per_spec = 0;
  };
  explicit WorkerPool(Options options);
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  // Ends every worker: closes their requests (they exit), then kills what is left.
  ~WorkerPool();

  // Queues a render; the returned ticket identifies its outcome.
  std::size_t submit(RenderRequest request);
  // Starts queued renders on idle workers (starting workers as needed) unless
  // `start_more` is false, waits up to wait_ms for replies, deaths and timeouts, and
  // returns what finished since the last call as (ticket, outcome).
  std::vector<std::pair<std::size_t, RenderOutcome>> poll(int wait_ms, bool start_more = true);
  // Renders queued or running.
  std::size_t outstanding() const { return queued_ + busy_; }
  // Workers started so far (restarts included).
  int workersStarted() const { return started_; }

  // Submits every request, waits for all, and returns their outcomes in order.
  std::vector<RenderOutcome> renderAll(const std::vector<RenderRequest>& requests);

 private:
  using Clock = std::chrono::steady_clock;
  struct Worker {
    std::string spec;
    pid_t pid = -1;
    int request_fd = -1;  // its stdin
    int reply_fd = -1;    // its fd 3, non-blocking here
    std::filesystem::path log;
    bool busy = false;
    bool single_use = false;  // started for a `fresh` request: ended after its reply
    std::size_t ticket = 0;
    Clock::time_point started;
    std::uintmax_t log_start = 0;
    // The current reply's bytes read so far (`filled` of `reply_size`): not zeroed first,
    // and kept for the next reply unless large.
    std::unique_ptr<char[]> reply;
    std::size_t reply_size = 0;
    std::size_t filled = 0;
  };
  struct Task {
    std::size_t ticket;
    RenderRequest request;
  };

  void dispatch();
  std::size_t workersFor(const std::string& spec) const;
  Worker* startWorker(const std::string& spec);
  bool send(Worker& w, const Task& task);
  void readReply(Worker& w, std::vector<std::pair<std::size_t, RenderOutcome>>& done);
  // Reaps a worker that ended (or kills it first); fails its render with `why` (when
  // busy), or with how it died when `why` is empty.
  void retire(Worker& w, const std::string& why,
              std::vector<std::pair<std::size_t, RenderOutcome>>& done, bool kill);
  std::string logSince(const Worker& w) const;

  Options options_;
  std::vector<std::unique_ptr<Worker>> workers_;
  // Queued renders per backend (and whether they want a fresh worker), each in submission
  // order: dispatch() looks at the fronts only, so a long queue costs nothing per render.
  std::map<std::pair<std::string, bool>, std::deque<Task>> queues_;
  std::size_t queued_ = 0;
  std::size_t next_ticket_ = 0;
  std::size_t busy_ = 0;
  // Per backend: renders finished and their seconds (from request to reply), for
  // workersFor()'s estimate of the work still queued.
  std::map<std::string, std::pair<std::size_t, double>> render_time_;
  int started_ = 0;
};

// The last non-empty line of a program's output without rastercheck's own "error:"
// prefixes: why a render failed, in one line.
std::string lastErrorLine(const std::string& output);

}  // namespace rc
