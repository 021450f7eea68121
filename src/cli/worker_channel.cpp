// The worker's line protocol and its test-only fault injection (see worker_channel.h).
#include "cli/worker_channel.h"

#include <unistd.h>

#include <csignal>
#include <cstdlib>

#include "common/error.h"

namespace topopt::cli {
namespace {

/// Ends or stalls the worker the way a fault in the core would. The signal handlers are
/// reset first so that nothing (OCCT's handlers included) turns the fault into an exception.
[[noreturn]] void inject_fault(const std::string& kind) {
  if (kind == "abort") {
    std::signal(SIGABRT, SIG_DFL);
    std::abort();
  }
  if (kind == "segv") {
    std::signal(SIGSEGV, SIG_DFL);
    std::raise(SIGSEGV);
  }
  for (;;) ::pause();  // "hang": alive, silent, until killed
}

}  // namespace

bool FaultPlan::matches(const std::string& s, const std::string& message) const {
  return !stage.empty() && s == stage && message.compare(0, word.size(), word) == 0;
}

FaultPlan fault_from_environment() {
  const char* value = std::getenv("TOPOPT_FAULT");
  FaultPlan plan;
  if (!value || !*value) return plan;
  const std::string v = value;
  const size_t colon = v.rfind(':');
  const std::string where = colon == std::string::npos ? "" : v.substr(0, colon);
  plan.kind = colon == std::string::npos ? "" : v.substr(colon + 1);
  if (where.empty() || (plan.kind != "abort" && plan.kind != "segv" && plan.kind != "hang"))
    throw Error(ErrorCode::InvalidParameter,
                "TOPOPT_FAULT='" + v + "': expected STAGE[/WORD]:abort|segv|hang (a test-only setting)");
  const size_t slash = where.find('/');
  plan.stage = where.substr(0, slash);
  if (slash != std::string::npos) plan.word = where.substr(slash + 1);
  return plan;
}

WorkerChannel::WorkerChannel() {
  std::fflush(stdout);
  const int protocol = ::dup(STDOUT_FILENO);
  ::dup2(STDERR_FILENO, STDOUT_FILENO);
  out_ = protocol >= 0 ? ::fdopen(protocol, "w") : nullptr;
  if (!out_) throw Error(ErrorCode::Internal, "the worker cannot keep its output channel");
}

WorkerChannel::~WorkerChannel() {
  if (out_) std::fclose(out_);
}

void WorkerChannel::send(const nlohmann::json& line, const std::string& stage, const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!stage.empty()) stage_ = stage;
  const std::string text = line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  std::fwrite(text.data(), 1, text.size(), out_);
  std::fflush(out_);
  if (!stage.empty() && fault_.matches(stage, message)) inject_fault(fault_.kind);
}

void WorkerChannel::progress(const std::string& stage, double fraction, const std::string& message) {
  send({{"stage", stage}, {"fraction", fraction}, {"message", message}}, stage, message);
}

void WorkerChannel::iteration(const simp::IterationRecord& rec) {
  send({{"iteration", rec.iteration},
        {"compliance", rec.compliance},
        {"volume", rec.volume_fraction},
        {"change", rec.change},
        {"seconds", rec.seconds}},
       "simp", "iteration " + std::to_string(rec.iteration));
}

void WorkerChannel::warning(const std::string& message) { send({{"warning", message}}, "", ""); }

void WorkerChannel::done() { send({{"done", true}}, "", ""); }

void WorkerChannel::error(const std::string& code, const std::string& message) {
  send({{"error", {{"code", code}, {"message", message}, {"stage", stage()}}}}, "", "");
}

Progress WorkerChannel::make_progress(std::vector<std::string>& warnings) {
  Progress p;
  p.report = [this](const std::string& stage, double fraction, const std::string& message) {
    if (stage != "simp") progress(stage, fraction, message);  // iterations come through iteration()
  };
  p.log = [this, &warnings](LogLevel level, const std::string& message) {
    if (level != LogLevel::Warning) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      warnings.push_back(message);
    }
    warning(message);
  };
  return p;
}

std::string WorkerChannel::stage() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stage_;
}

}  // namespace topopt::cli
