#include "common/error.h"

namespace topopt {

const char* error_code_name(ErrorCode code) {
  switch (code) {
    case ErrorCode::Io:
      return "Io";
    case ErrorCode::InvalidShape:
      return "InvalidShape";
    case ErrorCode::NonDesignOutside:
      return "NonDesignOutside";
    case ErrorCode::NonDesignOverlap:
      return "NonDesignOverlap";
    case ErrorCode::FaceNotFound:
      return "FaceNotFound";
    case ErrorCode::InvalidParameter:
      return "InvalidParameter";
    case ErrorCode::NoSupport:
      return "NoSupport";
    case ErrorCode::MeshingFailed:
      return "MeshingFailed";
    case ErrorCode::TooLarge:
      return "TooLarge";
    case ErrorCode::Cancelled:
      return "Cancelled";
    case ErrorCode::Timeout:
      return "Timeout";
    case ErrorCode::Crashed:
      return "Crashed";
    case ErrorCode::Internal:
      return "Internal";
  }
  return "Internal";
}

}  // namespace topopt
