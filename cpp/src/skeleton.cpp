#include "dcg/skeleton.h"

namespace dcg {

const char* node_kind_name(NodeKind kind) {
  switch (kind) {
    case NodeKind::End:
      return "end";
    case NodeKind::Joint:
      return "joint";
    case NodeKind::Connection:
      return "connection";
  }
  return "connection";
}

}  // namespace dcg
