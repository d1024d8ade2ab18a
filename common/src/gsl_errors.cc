#include "ccsrm/common/gsl_errors.h"

#include <gsl/gsl_errno.h>

#include <mutex>

namespace ccsrm {

void UseGslErrorCodes() {
  static std::once_flag once;
  std::call_once(once, [] { gsl_set_error_handler_off(); });
}

}  // namespace ccsrm
