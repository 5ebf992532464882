// The ACL reply parsers on arbitrary controller output: error lines and LISTPV values.
#include <cstdint>
#include <string>

#include "robots/acl_client.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  for (const oal::AclError& error : oal::ParseAclErrors(text)) {
    // What the parser promises: an axis is 0 or 1..5, a malformed line says why.
    if (error.axis < 0 || error.axis > 5) __builtin_trap();
    if ((error.kind == oal::AclErrorKind::kMalformed) == error.problem.empty()) __builtin_trap();
  }
  oal::AclPositionValues values;
  std::string why;
  oal::ParseListpv(text, &values, &why);
  return 0;
}
