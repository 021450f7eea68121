// Errors the user can act on. Broken invariants are assert()s; everything a user can cause
// (bad input, a front that cannot close, a singular system) is a topopt::Error with a code
// and a message that says what to change.
#pragma once
#include <stdexcept>
#include <string>

namespace topopt {

/// What kind of failure an Error reports. Bindings and the CLI map these to exit codes and
/// Python exception types; tests check the code, not the wording.
enum class ErrorCode {
  Io,                ///< file missing, unreadable, or in an unknown format
  InvalidShape,      ///< not a solid, not closed, invalid B-Rep that healing could not fix
  NonDesignOutside,  ///< a non-design solid is not inside the part
  NonDesignOverlap,  ///< two non-design solids share volume
  FaceNotFound,      ///< a face name (FaceN) that the part does not have
  InvalidParameter,  ///< an option out of range (volume fraction, sizes, ...)
  NoSupport,         ///< the structure is not held: stiffness matrix singular
  MeshingFailed,     ///< a front could not be closed; the message says where
  TooLarge,          ///< the requested mesh or system does not fit in memory
  Cancelled,         ///< the user cancelled through the Progress callback
  Timeout,           ///< a stage ran past its time budget and was stopped
  Crashed,           ///< isolated work (a child process) crashed; the caller is unharmed
  Internal           ///< a bug; please report
};

/// Short stable name of a code ("NonDesignOutside"), for JSON and Python.
const char* error_code_name(ErrorCode code);

/// The one exception type of the core. what() is the full, user-facing message.
class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ErrorCode code() const { return code_; }

 private:
  ErrorCode code_;
};

}  // namespace topopt
