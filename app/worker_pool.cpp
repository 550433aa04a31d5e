// See worker_pool.h: posix_spawn, pipes and one poll() loop in the calling thread.
#include "app/worker_pool.h"

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/backends.h"
#include "app/paths.h"
#include "app/subprocess.h"
#include "app/worker.h"
#include "fixtures/catalog.h"
#include "fixtures/errors.h"
#include "fixtures/frame_stream.h"

namespace rc {
namespace fs = std::filesystem;
namespace {

// What a log slice may contribute: a driver printing megabytes must not fill memory.
constexpr std::uintmax_t kMaxLogBytes = std::uintmax_t{64} * 1024;

void closeFd(int& fd) {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

bool names(const std::vector<std::string>& environment, std::string_view name) {
  return std::any_of(environment.begin(), environment.end(), [&](const std::string& e) {
    return e.size() > name.size() && e.compare(0, name.size(), name) == 0 && e[name.size()] == '=';
  });
}

// LP_NUM_THREADS for a GL worker (llvmpipe, and lavapipe under zink, read it; other drivers
// do not): the pool already runs one render per core, so a driver that also rasterizes on a
// thread per core oversubscribes them. With no rasterizer thread at all llvmpipe rasterizes
// in the render's own thread at glFinish and skips the hand-over: frames are the same bits
// (frame_digest of 800 random and 392 catalog frames on llvmpipe, zink and OSMesa llvmpipe
// with and without), and renders are faster even at 1920x1080 (docs/performance.md, "What
// a GL render costs now"). Cores left over per render go to the driver.
int rasterizerThreads(int max_busy) {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int per_render = cores / std::max(1, max_busy);
  return per_render >= 2 ? per_render : 0;
}

std::string howItEnded(int status) {
  if (WIFSIGNALED(status)) {
    const char* name = sigdescr_np(WTERMSIG(status));
    return fmt::format("crashed ({})", name ? name : fmt::format("signal {}", WTERMSIG(status)));
  }
  if (WIFEXITED(status)) return fmt::format("exited with code {}", WEXITSTATUS(status));
  return "ended";
}

std::string formatSeconds(double s) { return fmt::format("{:g} s", s); }

}  // namespace

std::string lastErrorLine(const std::string& output) {
  std::string last;
  std::size_t start = 0;
  while (start < output.size()) {
    std::size_t end = output.find('\n', start);
    if (end == std::string::npos) end = output.size();
    if (end > start) last = output.substr(start, end - start);
    start = end + 1;
  }
  for (const char* prefix :
       {"rastercheck: backend error: ", "rastercheck: error: ", "rastercheck: internal error: "}) {
    if (last.rfind(prefix, 0) == 0) last = last.substr(std::string(prefix).size());
  }
  return last;
}

WorkerPool::WorkerPool(Options options) : options_(std::move(options)) {
  options_.max_busy = std::max(1, options_.max_busy);
  // A worker that died leaves a broken request pipe: writing to it must fail, not kill us.
  std::signal(SIGPIPE, SIG_IGN);
  std::error_code ec;
  fs::create_directories(options_.log_dir, ec);
  if (ec)
    throw InputError(fmt::format("{}: cannot create: {}", options_.log_dir.string(), ec.message()));
}

WorkerPool::~WorkerPool() {
  for (auto& w : workers_) {
    if (w->busy) ::kill(w->pid, SIGKILL);
    closeFd(w->request_fd);  // an idle worker reads end-of-file and exits
  }
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  for (auto& w : workers_) {
    int status = 0;
    while (::waitpid(w->pid, &status, WNOHANG) == 0) {
      if (Clock::now() > deadline) {
        ::kill(w->pid, SIGKILL);
        ::waitpid(w->pid, &status, 0);
        break;
      }
      ::usleep(1000);
    }
    closeFd(w->reply_fd);
  }
}

std::size_t WorkerPool::submit(RenderRequest request) {
  std::deque<Task>& q = queues_[{request.spec, request.fresh}];
  q.push_back({next_ticket_, std::move(request)});
  ++queued_;
  return next_ticket_++;
}

WorkerPool::Worker* WorkerPool::startWorker(const std::string& spec) {
  int request[2];
  int reply[2];
  if (::pipe2(request, O_CLOEXEC) != 0) return nullptr;
  if (::pipe2(reply, O_CLOEXEC) != 0) {
    ::close(request[0]);
    ::close(request[1]);
    return nullptr;
  }
  // Frames are large; a bigger pipe means fewer wake-ups (best effort).
  ::fcntl(reply[0], F_SETPIPE_SZ, 1 << 20);
  auto w = std::make_unique<Worker>();
  w->spec = spec;
  w->log = options_.log_dir / fmt::format("{}-{}.log", fixtureSlug(spec), started_);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, request[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, reply[1], worker::kReplyFd);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, w->log.c_str(),
                                   O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  const std::string exe =
      options_.program.empty() ? selfExecutable().string() : options_.program.string();
  std::vector<std::string> args = {exe, "worker", "--backend", spec};
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  // A spec naming another Mesa's folder needs LD_LIBRARY_PATH from the worker's start (the
  // dynamic loader reads it once), as `render` re-executes itself with it.
  std::vector<std::string> extra = options_.environment;
  const BackendSpec backend = parseBackendSpec(spec);
  if (backend.kind == BackendSpec::Kind::Gl) {
    for (const auto& [name, value] : startupEnvironment(backend.gl))
      extra.push_back(fmt::format("{}={}", name, value));
    // The user's own setting wins.
    if (std::getenv("LP_NUM_THREADS") == nullptr && !names(extra, "LP_NUM_THREADS"))
      extra.push_back(fmt::format("LP_NUM_THREADS={}", rasterizerThreads(options_.max_busy)));
  }
  std::vector<std::string> env_text = childEnvironment(extra);
  std::vector<char*> envp;
  envp.reserve(env_text.size() + 1);
  for (std::string& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);
  const int err = posix_spawn(&w->pid, exe.c_str(), &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  ::close(request[0]);
  ::close(reply[1]);
  if (err != 0) {
    ::close(request[1]);
    ::close(reply[0]);
    throw BackendError(fmt::format("cannot start {}: {}", exe, std::strerror(err)));
  }
  w->request_fd = request[1];
  w->reply_fd = reply[0];
  ::fcntl(w->reply_fd, F_SETFL, ::fcntl(w->reply_fd, F_GETFL) | O_NONBLOCK);
  ++started_;
  workers_.push_back(std::move(w));
  return workers_.back().get();
}

bool WorkerPool::send(Worker& w, const Task& task) {
  nlohmann::json request{{"id", task.ticket}, {"fixture", task.request.fixture.string()}};
  if (!task.request.fault.empty()) request["fault"] = task.request.fault;
  if (task.request.pass_frames) request["pass_frames"] = true;
  const std::string line =
      request.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  std::error_code ec;
  w.log_start = fs::file_size(w.log, ec);
  if (ec) w.log_start = 0;
  const char* p = line.data();
  std::size_t left = line.size();
  while (left > 0) {
    const ssize_t n = ::write(w.request_fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;  // the worker is gone
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  w.busy = true;
  w.ticket = task.ticket;
  w.started = Clock::now();
  w.filled = 0;
  ++busy_;
  return true;
}

std::size_t WorkerPool::workersFor(const std::string& spec) const {
  if (options_.max_workers_per_spec > 0)
    return static_cast<std::size_t>(options_.max_workers_per_spec);
  // llvmpipe, and lavapipe under zink, JIT-compile every state variant in each process: a
  // second worker of the driver would compile them all again (tried: what it saved, its start
  // and JIT cost). With cores to spare they rasterize on threads of their own
  // (rasterizerThreads).
  const BackendSpec b = parseBackendSpec(spec);
  if (b.kind == BackendSpec::Kind::Gl && (b.gl.driver == "llvmpipe" || b.gl.driver == "zink"))
    return 1;
  // The reference and softpipe draw on one thread: one more worker when other backends'
  // queued renders cannot fill the other busy slots, and what is queued for this one (its
  // renders so far, on average) outweighs a worker's start: ~0.2 s of loading a GL driver,
  // ~0.03 s for the reference (no driver). Measured on 200 small scenes: softpipe's 26 ms
  // renders are worth a second worker when it renders alone; beside three other drivers a
  // second softpipe worker made the run slower (6.6 s against 5.9 s). The reference, whose
  // worker runs at a lower priority (worker.cpp), is often the last one drawing: with
  // llvmpipe done, a second worker halves the tail it draws alone.
  const double kQueuedWorkForAWorker = b.kind == BackendSpec::Kind::Reference ? 0.1 : 0.5;
  std::set<std::string> others;
  for (const auto& [key, q] : queues_)
    if (!q.empty() && key.first != spec) others.insert(key.first);
  if (others.size() + 1 >= static_cast<std::size_t>(options_.max_busy)) return 1;
  const auto it = render_time_.find(spec);
  if (it == render_time_.end() || it->second.first == 0) return 1;
  const double mean = it->second.second / static_cast<double>(it->second.first);
  const auto mine = queues_.find({spec, false});
  const double queued = mine == queues_.end() ? 0.0 : static_cast<double>(mine->second.size());
  return queued * mean > kQueuedWorkForAWorker ? static_cast<std::size_t>(options_.max_busy) : 1;
}

void WorkerPool::dispatch() {
  auto idleFor = [&](const RenderRequest& r) -> Worker* {
    if (r.fresh) return nullptr;
    for (auto& w : workers_)
      if (!w->busy && !w->single_use && w->spec == r.spec) return w.get();
    return nullptr;
  };
  auto roomFor = [&](const RenderRequest& r) {
    if (r.fresh) return true;
    return static_cast<std::size_t>(std::count_if(workers_.begin(), workers_.end(), [&](auto& w) {
             return !w->single_use && w->spec == r.spec;
           })) < workersFor(r.spec);
  };
  while (queued_ > 0 && busy_ < static_cast<std::size_t>(options_.max_busy)) {
    // The earliest queued render that can start now: on an idle worker of its backend, or
    // on a new one while the backend has fewer than workersFor() (renders of one backend
    // keep their order; another backend's may go first; outcomes are matched by ticket).
    std::deque<Task>* from = nullptr;
    for (auto& [key, q] : queues_) {
      if (q.empty() || (from != nullptr && q.front().ticket > from->front().ticket)) continue;
      if (idleFor(q.front().request) != nullptr || roomFor(q.front().request)) from = &q;
    }
    if (from == nullptr) return;
    const Task task = std::move(from->front());
    from->pop_front();
    --queued_;
    Worker* idle = idleFor(task.request);
    if (idle != nullptr && send(*idle, task)) continue;
    if (idle != nullptr) {
      // It died while idle (nothing lost): reap it and start another.
      std::vector<std::pair<std::size_t, RenderOutcome>> none;
      retire(*idle, "", none, true);
    }
    Worker* fresh = startWorker(task.request.spec);
    if (fresh != nullptr) fresh->single_use = task.request.fresh;
    if (fresh == nullptr || !send(*fresh, task))
      throw BackendError(
          fmt::format("cannot start a worker for {}: {}", task.request.spec, std::strerror(errno)));
  }
}

std::string WorkerPool::logSince(const Worker& w) const {
  std::error_code ec;
  const std::uintmax_t end = fs::file_size(w.log, ec);
  if (ec || end <= w.log_start) return {};
  const std::uintmax_t start = std::max(w.log_start, end - std::min(end, kMaxLogBytes));
  std::ifstream in(w.log, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(start));
  std::string text(end - start, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  return text;
}

void WorkerPool::retire(Worker& w, const std::string& why,
                        std::vector<std::pair<std::size_t, RenderOutcome>>& done, bool kill) {
  if (kill) ::kill(w.pid, SIGKILL);
  int status = 0;
  while (::waitpid(w.pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (w.busy) {
    RenderOutcome out;
    out.log = logSince(w);
    const std::string last = lastErrorLine(out.log);
    out.error = why.empty() ? howItEnded(status) + (last.empty() ? "" : ": " + last) : why;
    done.emplace_back(w.ticket, std::move(out));
    --busy_;
  }
  closeFd(w.request_fd);
  closeFd(w.reply_fd);
  w.pid = -1;
  std::erase_if(workers_, [&](const std::unique_ptr<Worker>& p) { return p.get() == &w; });
}

// A reply buffer up to this size is kept for the worker's next reply (no allocation and
// page faults per frame); a larger one is given back.
constexpr std::size_t kKeptReplyBytes = std::size_t{16} << 20;

void WorkerPool::readReply(Worker& w, std::vector<std::pair<std::size_t, RenderOutcome>>& done) {
  constexpr std::size_t kHeader = sizeof(worker::ReplyHeader);
  constexpr std::uint64_t kMaxPayload = std::uint64_t{1} << 36;
  for (;;) {
    // The header first, then exactly the payload it announces.
    std::size_t want = kHeader;
    if (w.filled >= kHeader) {
      worker::ReplyHeader h{};
      std::memcpy(&h, w.reply.get(), kHeader);
      if (std::memcmp(h.tag, worker::kReplyTag, sizeof h.tag) != 0 || !w.busy || h.id != w.ticket ||
          h.length > kMaxPayload) {
        retire(w, "sent a malformed reply", done, true);
        return;
      }
      want = kHeader + h.length;
      if (w.filled == want) {
        RenderOutcome out;
        const std::string_view payload(w.reply.get() + kHeader, h.length);
        out.log = logSince(w);
        if (h.kind == worker::ReplyKind::Frame) {
          try {
            out.frame = decodeFrame(payload);
            out.ok = true;
          } catch (const InputError& e) {
            out.error = e.what();
          }
        } else {
          out.error = std::string(payload);
          out.input_error = h.kind == worker::ReplyKind::InputError;
        }
        done.emplace_back(w.ticket, std::move(out));
        auto& [renders, seconds] = render_time_[w.spec];
        ++renders;
        seconds += std::chrono::duration<double>(Clock::now() - w.started).count();
        w.busy = false;
        --busy_;
        if (w.reply_size > kKeptReplyBytes) {
          w.reply.reset();
          w.reply_size = 0;
        }
        w.filled = 0;
        if (w.single_use) retire(w, "", done, true);  // its one render is done
        return;
      }
    }
    if (w.reply_size < want) {
      auto bigger = std::make_unique_for_overwrite<char[]>(want);
      if (w.filled > 0) std::memcpy(bigger.get(), w.reply.get(), w.filled);
      w.reply = std::move(bigger);
      w.reply_size = want;
    }
    const ssize_t n = ::read(w.reply_fd, w.reply.get() + w.filled, want - w.filled);
    if (n > 0) {
      w.filled += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return;
    retire(w, "", done, false);  // end of file: the worker ended
    return;
  }
}

std::vector<std::pair<std::size_t, RenderOutcome>> WorkerPool::poll(int wait_ms, bool start_more) {
  std::vector<std::pair<std::size_t, RenderOutcome>> done;
  if (start_more) dispatch();
  // Sleep at most until the first watchdog deadline.
  auto now = Clock::now();
  int timeout = wait_ms;
  const auto limit = std::chrono::duration<double>(options_.timeout_seconds);
  if (options_.timeout_seconds > 0.0) {
    for (const auto& w : workers_) {
      if (!w->busy) continue;
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          w->started + std::chrono::duration_cast<Clock::duration>(limit) - now);
      timeout = std::max(0, std::min(timeout, static_cast<int>(left.count()) + 1));
    }
  }
  std::vector<pollfd> fds;
  std::vector<Worker*> owners;
  for (const auto& w : workers_) {
    fds.push_back({w->reply_fd, POLLIN, 0});
    owners.push_back(w.get());
  }
  if (::poll(fds.data(), fds.size(), timeout) < 0 && errno != EINTR)
    throw BackendError(fmt::format("poll failed: {}", std::strerror(errno)));
  for (std::size_t i = 0; i < fds.size(); ++i)
    if (fds[i].revents != 0) readReply(*owners[i], done);  // may retire that worker
  // The watchdog: a render past its time loses its worker.
  if (options_.timeout_seconds > 0.0) {
    now = Clock::now();
    std::vector<Worker*> late;
    for (const auto& w : workers_)
      if (w->busy && now - w->started >= limit) late.push_back(w.get());
    for (Worker* w : late)
      retire(*w,
             fmt::format("timed out after {} (the --timeout watchdog killed its worker)",
                         formatSeconds(options_.timeout_seconds)),
             done, true);
  }
  if (start_more) dispatch();
  return done;
}

std::vector<RenderOutcome> WorkerPool::renderAll(const std::vector<RenderRequest>& requests) {
  std::vector<std::size_t> tickets;
  tickets.reserve(requests.size());
  for (const RenderRequest& r : requests) tickets.push_back(submit(r));
  std::vector<RenderOutcome> out(requests.size());
  std::size_t left = requests.size();
  while (left > 0) {
    for (auto& [ticket, outcome] : poll(1000)) {
      const auto it = std::find(tickets.begin(), tickets.end(), ticket);
      if (it == tickets.end()) continue;
      out[static_cast<std::size_t>(it - tickets.begin())] = std::move(outcome);
      --left;
    }
  }
  return out;
}

}  // namespace rc
