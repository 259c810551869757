// build_commit(): the one translation unit that includes the generated commit header, so a new
// commit recompiles this file only.
#include "firmware/commands.hpp"
#include "storey_commit.hpp"

namespace storey::firmware {
const char* build_commit() {
  return STOREY_COMMIT;
}
}  // namespace storey::firmware
