// run_isolated: fork, a pipe for the answer, poll with a deadline (see isolate.h).
#include "common/isolate.h"

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <exception>

namespace topopt {
namespace {

// The answer on the pipe: one status byte, then the payload.
//   'R' result bytes | 'E' code byte + message | 'X' message of a foreign exception
void write_all(int fd, const char* data, size_t n) {
  while (n > 0) {
    ssize_t k = ::write(fd, data, n);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return;
    data += k, n -= static_cast<size_t>(k);
  }
}

[[noreturn]] void child_main(int fd, const std::function<std::string()>& work) {
  std::string answer;
  try {
    answer = "R" + work();
  } catch (const Error& e) {
    answer = std::string("E") + static_cast<char>(e.code()) + e.what();
  } catch (const std::exception& e) {
    answer = std::string("X") + e.what();
  } catch (...) {
    answer = "Xan unknown exception";
  }
  write_all(fd, answer.data(), answer.size());
  ::close(fd);
  ::_exit(0);
}

std::string signal_name(int sig) {
  const char* s = strsignal(sig);
  return std::string(s ? s : "signal") + " (signal " + std::to_string(sig) + ")";
}

/// Reads the child's answer until EOF; false when the deadline or a cancel came first. The deadline is
/// exact: an answer that ends after it counts as late, however short the budget.
bool read_answer(int fd, double seconds, const Progress& progress, std::string& answer, bool& cancelled) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  char buf[1 << 16];
  for (;;) {
    int wait_ms = 100;
    if (seconds > 0) wait_ms = static_cast<int>(std::clamp(1000.0 * (seconds - elapsed()) + 1.0, 0.0, 100.0));
    pollfd p{fd, POLLIN, 0};
    int r = ::poll(&p, 1, wait_ms);
    if (r < 0 && errno != EINTR) return true;
    if (seconds > 0 && elapsed() > seconds) return false;
    if (r > 0) {
      ssize_t k = ::read(fd, buf, sizeof buf);
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0) return true;  // EOF: the child closed its end (answered or died)
      answer.append(buf, static_cast<size_t>(k));
      continue;
    }
    if (progress.cancelled && progress.cancelled()) return !(cancelled = true);
  }
}

}  // namespace

std::string run_isolated(const std::string& what, double seconds, const std::function<std::string()>& work,
                         const Progress& progress) {
  const char* off = std::getenv("TOPOPT_NO_ISOLATION");
  if (off && std::string(off) == "1") return work();
  int fds[2];
  if (::pipe(fds) != 0) throw Error(ErrorCode::Internal, what + ": cannot create a pipe: " + std::strerror(errno));
  pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]), ::close(fds[1]);
    throw Error(ErrorCode::TooLarge,
                what + ": cannot start a child process (" + std::strerror(errno) + "): free some memory and try again");
  }
  if (pid == 0) {
    ::close(fds[0]);
    child_main(fds[1], work);
  }
  ::close(fds[1]);
  std::string answer;
  bool cancelled = false;
  bool finished = read_answer(fds[0], seconds, progress, answer, cancelled);
  ::close(fds[0]);
  if (!finished) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (cancelled) throw Error(ErrorCode::Cancelled, "cancelled during " + what);
  if (!finished)
    throw Error(ErrorCode::Timeout,
                what + " did not finish within " + std::to_string(static_cast<int>(seconds)) + " s and was stopped");
  if (WIFSIGNALED(status) || answer.empty())
    throw Error(ErrorCode::Crashed,
                what + " crashed" + (WIFSIGNALED(status) ? " with " + signal_name(WTERMSIG(status)) : std::string()) +
                    " and was stopped; nothing else was affected");
  char kind = answer[0];
  if (kind == 'R') return answer.substr(1);
  if (kind == 'E' && answer.size() >= 2) throw Error(static_cast<ErrorCode>(answer[1]), answer.substr(2));
  throw Error(ErrorCode::Internal, what + ": " + answer.substr(1));
}

}  // namespace topopt
