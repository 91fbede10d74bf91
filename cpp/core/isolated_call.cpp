#include "core/isolated_call.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <new>
#include <optional>
#include <sstream>
#include <string>

#include "core/format.hpp"
#include "core/system_memory.hpp"

namespace homesh {
namespace {

// The child's answer: one kind byte, then the result's bytes or the error's message.
constexpr char kResult = 'R', kParameter = 'P', kIo = 'I', kCad = 'C', kMeshing = 'M',
               kCancelled = 'X', kOther = 'E', kMemory = 'A';
// With a start probe, the byte the child sends before the answer once the probe has returned.
constexpr char kStarted = 'S';

bool writeAll(int fd, const char* data, std::size_t n) {
  while (n > 0) {
    const ssize_t written = ::write(fd, data, n);
    if (written < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += written;
    n -= static_cast<std::size_t>(written);
  }
  return true;
}

// `output`: where the child's stdout and stderr go (the watched pipe), or -1 to keep them.
[[noreturn]] void runChild(int fd, int output, pid_t parent, const IsolationLimits& limits,
                           const std::function<std::string()>& work) {
  // A crash must end the child with its signal, whatever handlers the caller (FreeCAD) set, and
  // the child must not outlive the thread that waits for it (nor start after it died).
  for (const int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGPIPE, SIGTERM, SIGINT})
    std::signal(sig, SIG_DFL);
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (getppid() != parent) _exit(3);
  // Only stdin, stdout, stderr (the watched pipe, if any) and the result pipe (as 3) stay open:
  // the caller's other files, pipes and sockets (FreeCAD's) must not be held open by a child that
  // may run for minutes. Both pipes are first moved above 3, so that neither is overwritten
  // whichever numbers they had (1 or 2 where the caller had closed its stdout or stderr).
  const bool watched = output >= 0;
  fd = fcntl(fd, F_DUPFD, 4);
  if (watched) output = fcntl(output, F_DUPFD, 4);
  if (fd < 0 || (watched && output < 0)) _exit(3);
  if (watched && (dup2(output, STDOUT_FILENO) < 0 || dup2(output, STDERR_FILENO) < 0)) _exit(3);
  if (dup2(fd, 3) < 0) _exit(3);
  fd = 3;
  close_range(4, ~0U, 0);
  const std::size_t extra = limits.extraBytes > 0 ? limits.extraBytes : availableMemoryBytes();
  if (extra > 0) {
    rlimit limit{};
    limit.rlim_cur = limit.rlim_max = addressSpaceBytes() + extra;
    setrlimit(RLIMIT_AS, &limit);
  }
  if (limits.startProbe) {
    limits.startProbe();
    if (!writeAll(fd, &kStarted, 1)) _exit(3);
  }
  char kind = kResult;
  std::string payload;
  try {
    payload = work();
  } catch (const std::bad_alloc&) {
    kind = kMemory;
    payload.clear();
  } catch (const CancelledError& e) {
    kind = kCancelled;
    payload = e.what();
  } catch (const ParameterError& e) {
    kind = kParameter;
    payload = e.what();
  } catch (const IoError& e) {
    kind = kIo;
    payload = e.what();
  } catch (const CadError& e) {
    kind = kCad;
    payload = e.what();
  } catch (const MeshingError& e) {
    kind = kMeshing;
    payload = e.what();
  } catch (const std::exception& e) {
    kind = kOther;
    payload = e.what();
  } catch (...) {
    kind = kOther;
    payload = "an exception of unknown type";
  }
  if (watched) std::fflush(nullptr);  // what the work left buffered, for the watch
  const bool sent = writeAll(fd, &kind, 1) && writeAll(fd, payload.data(), payload.size());
  ::close(fd);
  // _exit: no atexit handlers, no flushing of the caller's stdio buffers a second time.
  _exit(sent ? 0 : 3);
}

std::string signalName(int sig) {
  // sigabbrev_np is thread-safe, unlike strsignal.
  const char* name = sigabbrev_np(sig);
  switch (sig) {
    case SIGSEGV:
      return "Segmentation fault";
    case SIGABRT:
      return "Aborted";
    case SIGBUS:
      return "Bus error";
    case SIGFPE:
      return "Floating point exception";
    case SIGILL:
      return "Illegal instruction";
    case SIGKILL:
      return "Killed";
    default:
      return name != nullptr ? "SIG" + std::string(name) : "signal " + std::to_string(sig);
  }
}

using Clock = std::chrono::steady_clock;

// A forked child running `work`, the read end of the pipe it answers on and, when it is
// watched, of the pipe its stdout and stderr go to. Whatever happens while it runs (an
// allocation failing, a cancel callback throwing), the child is killed and reaped and the pipes
// closed when this is dropped.
class Child {
 public:
  Child(const std::string& what, const IsolationLimits& limits,
        const std::function<std::string()>& work) {
    std::array<int, 2> fds{-1, -1}, out{-1, -1};
    const auto closeAll = [&] {
      for (const int f : {fds[0], fds[1], out[0], out[1]})
        if (f >= 0) ::close(f);
    };
    if (pipe2(fds.data(), O_CLOEXEC) != 0 || (limits.watch && pipe2(out.data(), O_CLOEXEC) != 0)) {
      const int error = errno;
      closeAll();
      throw Error("cannot start a process for " + what + ": " + std::strerror(error));
    }
    std::fflush(nullptr);
    const pid_t parent = getpid();
    pid_ = fork();
    if (pid_ < 0) {
      const int error = errno;
      closeAll();
      throw Error("cannot start a process for " + what + ": " + std::strerror(error));
    }
    if (pid_ == 0) {
      ::close(fds[0]);
      if (out[0] >= 0) ::close(out[0]);
      runChild(fds[1], out[1], parent, limits, work);
    }
    ::close(fds[1]);
    if (out[1] >= 0) ::close(out[1]);
    fd_ = fds[0];
    output_ = out[0];
    reaped_ = false;
  }
  ~Child() { reap(true); }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  Child(Child&&) = delete;
  Child& operator=(Child&&) = delete;

  int fd() const { return fd_; }
  int output() const { return output_; }  // -1 when not watched
  // Closes the pipes and waits for the child, killing it first if `kill`; once only.
  void reap(bool kill) {
    if (reaped_) return;
    ::close(fd_);
    if (output_ >= 0) ::close(output_);
    if (kill) ::kill(pid_, SIGKILL);
    while ((waited_ = waitpid(pid_, &status_, 0)) < 0 && errno == EINTR) {
    }
    reaped_ = true;
  }
  // The child's wait status once reaped, if waitpid gave it.
  std::optional<int> status() const {
    return waited_ == pid_ ? std::optional<int>(status_) : std::nullopt;
  }

 private:
  pid_t pid_ = -1;
  int fd_ = -1;
  int output_ = -1;
  bool reaped_ = true;
  int status_ = 0;
  pid_t waited_ = 0;
};

// How the wait for a child's answer ended.
enum class WaitEnd { Closed, Stuck, Cancelled, OverTime, Stalled };

// A watched child's output, cut into lines for limits.watch; remembers the first stall.
class WatchedOutput {
 public:
  explicit WatchedOutput(const IsolationLimits& limits) : watch_(limits.watch) {}
  void add(const char* data, std::size_t n) {
    pending_.append(data, n);
    std::size_t from = 0;
    // Gmsh's progress meter ends its lines with a carriage return.
    for (std::size_t end = 0; (end = pending_.find_first_of("\n\r", from)) != std::string::npos;
         from = end + 1)
      see(pending_.substr(from, end - from));
    pending_.erase(0, from);
  }
  // The last line, if it had no newline.
  void finish() {
    if (!pending_.empty()) see(pending_);
    pending_.clear();
  }
  const std::string& stall() const { return stall_; }

 private:
  void see(const std::string& line) {
    std::string answer = watch_(line);
    if (stall_.empty()) stall_ = std::move(answer);
  }
  const std::function<std::string(const std::string&)>& watch_;
  std::string pending_, stall_;
};

// Reads what is ready on `fd` into `to`; false once the writer closed its end.
template <class Append>
bool readReady(int fd, const std::string& what, Append&& to) {  // `what`: "the result of ..."
  std::array<char, 65536> buffer{};
  const ssize_t n = ::read(fd, buffer.data(), buffer.size());
  if (n > 0) {
    to(buffer.data(), static_cast<std::size_t>(n));
    return true;
  }
  if (n == 0) return false;
  if (errno == EINTR || errno == EAGAIN) return true;
  throw Error("cannot read " + what + ": " + std::strerror(errno));
}

// Reads the child's answer into `bytes` until it closes its end, the caller cancels, the budget
// (counted from `start`) is spent, the watch of its output says it stalls (`output`), or
// (`awaitStart`, not the last attempt) the start probe has not returned within
// limits.startSeconds.
WaitEnd readAnswer(const Child& child, const std::string& what, const IsolationLimits& limits,
                   Clock::time_point start, bool awaitStart, bool lastAttempt, std::string& bytes,
                   WatchedOutput& output) {
  const auto forked = Clock::now();
  bool started = !awaitStart;
  bytes.clear();
  std::array<pollfd, 2> in{pollfd{child.fd(), POLLIN, 0}, pollfd{child.output(), POLLIN, 0}};
  const auto watched = [&](const char* data, std::size_t n) { output.add(data, n); };
  for (;;) {
    const int ready = poll(in.data(), in.size(), 50);
    if (ready < 0 && errno != EINTR)
      throw Error("cannot wait for " + what + ": " + std::strerror(errno));
    if (ready > 0 && in[1].revents != 0 && !readReady(in[1].fd, "the output of " + what, watched)) {
      output.finish();
      in[1].fd = -1;  // poll skips it from now on
    }
    // The answer first: a child that has finished is not taken for stalled.
    if (ready > 0 && in[0].revents != 0 &&
        !readReady(in[0].fd, "the result of " + what, [&](const char* data, std::size_t n) {
          bytes.append(data, n);
          if (!started) {
            started = bytes[0] == kStarted;
            if (started) bytes.erase(0, 1);
          }
        })) {
      // The child closed its end (finished or died): what it wrote last is read to its end (it
      // closes with the child's exit), for at most a second.
      const auto deadline = Clock::now() + std::chrono::seconds(1);
      for (pollfd last{in[1].fd, POLLIN, 0}; last.fd >= 0 && Clock::now() < deadline;) {
        const int more = poll(&last, 1, 100);
        if ((more < 0 && errno != EINTR) ||
            (more > 0 && !readReady(last.fd, "the output of " + what, watched)))
          break;
      }
      output.finish();
      return WaitEnd::Closed;
    }
    if (!output.stall().empty()) return WaitEnd::Stalled;
    if (limits.cancelled && limits.cancelled()) return WaitEnd::Cancelled;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (limits.seconds > 0.0 && elapsed > limits.seconds) return WaitEnd::OverTime;
    if (!started && !lastAttempt &&
        std::chrono::duration<double>(Clock::now() - forked).count() > limits.startSeconds)
      return WaitEnd::Stuck;
  }
}

// A child that died by a signal or ended without an answer: the error that says so.
void throwIfNoAnswer(const std::string& what, std::optional<int> status, const std::string& bytes) {
  if (status && WIFSIGNALED(*status)) {
    const int sig = WTERMSIG(*status);
    if (sig == SIGKILL)
      throw OutOfMemory(what + " was killed (" + signalName(sig) +
                        "), most likely by the system for lack of memory");
    throw ChildCrashed(what + " crashed (" + signalName(sig) + ")");
  }
  if (bytes.empty() || (status && WIFEXITED(*status) && WEXITSTATUS(*status) != 0))
    throw ChildCrashed(what + " ended without a result" +
                       (status && WIFEXITED(*status)
                            ? " (exit status " + std::to_string(WEXITSTATUS(*status)) + ")"
                            : std::string()));
}

// The child's answer: its result, or its error thrown again with its type.
std::string unpackAnswer(const std::string& what, const std::string& bytes) {
  const char kind = bytes[0];
  std::string payload = bytes.substr(1);
  switch (kind) {
    case kResult:
      return payload;
    case kMemory:
      throw OutOfMemory(
          what + " ran out of memory (the machine had " +
          formatNumber(std::round(static_cast<double>(availableMemoryBytes()) / 1e8) / 10) +
          " GB available)");
    case kCancelled:
      throw CancelledError(payload);
    case kParameter:
      throw ParameterError(payload);
    case kIo:
      throw IoError(payload);
    case kCad:
      throw CadError(payload);
    case kMeshing:
      throw MeshingError(payload);
    default:
      throw Error(what + " failed: " + payload);
  }
}

}  // namespace

std::string runIsolated(const std::string& what, const IsolationLimits& limits,
                        const std::function<std::string()>& work) {
  const auto start = Clock::now();  // the budget counts from the first child
  const bool probed = static_cast<bool>(limits.startProbe);
  const int attempts = probed ? std::max(1, limits.startAttempts) : 1;
  std::string bytes;
  std::optional<Child> child;
  std::optional<WatchedOutput> output;
  WaitEnd end = WaitEnd::Closed;
  for (int attempt = 1;; ++attempt) {
    child.emplace(what, limits, work);
    output.emplace(limits);
    end = readAnswer(*child, what, limits, start, probed, attempt >= attempts, bytes, *output);
    if (end != WaitEnd::Stuck) break;
    child.reset();  // killed and reaped before the next attempt starts
    if (limits.restarted) limits.restarted(attempt);
  }
  child->reap(end != WaitEnd::Closed);

  if (end == WaitEnd::Cancelled) throw CancelledError("cancelled during " + what);
  if (end == WaitEnd::Stalled)
    throw Stalled(
        what + " made no progress after " +
        formatNumber(std::round(std::chrono::duration<double>(Clock::now() - start).count())) +
        " s: " + output->stall());
  if (end == WaitEnd::OverTime)
    throw BudgetExceeded(
        what + " stopped at its time budget of " +
        formatNumber(limits.statedSeconds > 0.0 ? limits.statedSeconds : limits.seconds) + " s" +
        (limits.budgetName.empty() ? "" : " (" + limits.budgetName + ")"));
  throwIfNoAnswer(what, child->status(), bytes);
  return unpackAnswer(what, bytes);
}

}  // namespace homesh
