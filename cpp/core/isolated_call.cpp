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
#include <sstream>

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

[[noreturn]] void runChild(int fd, pid_t parent, const IsolationLimits& limits,
                           const std::function<std::string()>& work) {
  // A crash must end the child with its signal, whatever handlers the caller (FreeCAD) set, and
  // the child must not outlive the thread that waits for it (nor start after it died).
  for (const int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGPIPE, SIGTERM, SIGINT})
    std::signal(sig, SIG_DFL);
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (getppid() != parent) _exit(3);
  // Only stdin, stdout, stderr and the result pipe stay open: the caller's other files, pipes
  // and sockets (FreeCAD's) must not be held open by a child that may run for minutes.
  if (fd != 3) {
    if (dup2(fd, 3) < 0) _exit(3);
    fd = 3;
  }
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

}  // namespace

std::string runIsolated(const std::string& what, const IsolationLimits& limits,
                        const std::function<std::string()>& work) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();  // the budget counts from the first child
  const bool probed = static_cast<bool>(limits.startProbe);
  const int attempts = probed ? std::max(1, limits.startAttempts) : 1;
  std::array<int, 2> fds{-1, -1};
  pid_t pid = -1;
  // Whatever happens below (an allocation failing, a cancel callback throwing), the child is
  // killed and reaped and the pipe closed; `reaped` once waitpid has run.
  bool reaped = true;
  int status = 0;
  pid_t waited = 0;
  const auto reap = [&](bool kill) {
    if (reaped) return;
    ::close(fds[0]);
    if (kill) ::kill(pid, SIGKILL);
    while ((waited = waitpid(pid, &status, 0)) < 0 && errno == EINTR) {
    }
    reaped = true;
  };
  struct Guard {
    std::function<void()> onExit;
    ~Guard() { onExit(); }
  } guard{[&] { reap(true); }};

  std::string bytes;
  std::array<char, 65536> buffer{};
  bool overTime = false, cancelled = false;
  for (int attempt = 1;; ++attempt) {
    if (pipe2(fds.data(), O_CLOEXEC) != 0)
      throw Error("cannot start a process for " + what + ": " + std::strerror(errno));
    std::fflush(nullptr);
    const pid_t parent = getpid();
    pid = fork();
    if (pid < 0) {
      const int error = errno;
      ::close(fds[0]);
      ::close(fds[1]);
      throw Error("cannot start a process for " + what + ": " + std::strerror(error));
    }
    if (pid == 0) {
      ::close(fds[0]);
      runChild(fds[1], parent, limits, work);
    }
    ::close(fds[1]);
    reaped = false;
    const auto forked = Clock::now();
    const bool lastAttempt = attempt >= attempts;
    bool started = !probed, stuck = false;
    bytes.clear();
    for (;;) {
      pollfd in{fds[0], POLLIN, 0};
      const int ready = poll(&in, 1, 50);
      if (ready > 0) {
        const ssize_t n = ::read(fds[0], buffer.data(), buffer.size());
        if (n > 0) {
          bytes.append(buffer.data(), static_cast<std::size_t>(n));
          if (!started) {
            started = bytes[0] == kStarted;
            if (started) bytes.erase(0, 1);
          }
        } else if (n == 0) {
          break;  // the child closed its end (finished or died)
        } else if (errno != EINTR) {
          throw Error("cannot read the result of " + what + ": " + std::strerror(errno));
        }
      } else if (ready < 0 && errno != EINTR) {
        throw Error("cannot wait for " + what + ": " + std::strerror(errno));
      }
      if (limits.cancelled && limits.cancelled()) {
        cancelled = true;
        break;
      }
      const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
      if (limits.seconds > 0.0 && elapsed > limits.seconds) {
        overTime = true;
        break;
      }
      if (!started && !lastAttempt &&
          std::chrono::duration<double>(Clock::now() - forked).count() > limits.startSeconds) {
        stuck = true;
        break;
      }
    }
    if (!stuck) break;
    reap(true);
    if (limits.restarted) limits.restarted(attempt);
  }
  reap(cancelled || overTime);

  if (cancelled) throw CancelledError("cancelled during " + what);
  if (overTime)
    throw BudgetExceeded(
        what + " stopped at its time budget of " +
        formatNumber(limits.statedSeconds > 0.0 ? limits.statedSeconds : limits.seconds) + " s" +
        (limits.budgetName.empty() ? "" : " (" + limits.budgetName + ")"));
  if (waited == pid && WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    if (sig == SIGKILL)
      throw OutOfMemory(what + " was killed (" + signalName(sig) +
                        "), most likely by the system for lack of memory");
    throw ChildCrashed(what + " crashed (" + signalName(sig) + ")");
  }
  if (bytes.empty() || (waited == pid && WIFEXITED(status) && WEXITSTATUS(status) != 0))
    throw ChildCrashed(what + " ended without a result" +
                       (waited == pid && WIFEXITED(status)
                            ? " (exit status " + std::to_string(WEXITSTATUS(status)) + ")"
                            : std::string()));
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

}  // namespace homesh
