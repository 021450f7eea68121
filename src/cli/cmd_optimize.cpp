// topopt optimize: not built yet; the issue that brings this stage replaces this file.
#include "cli/commands.h"
#include "common/error.h"

namespace topopt::cli {

int cmd_optimize(const Args&) {
  throw Error(ErrorCode::Internal, "'topopt optimize' is not available in this build yet");
}

}  // namespace topopt::cli
