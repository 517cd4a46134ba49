#pragma once
// The library validates its option structs and names their fields in the messages
// ("radius_ratio = 0.5 is not allowed: it must be >= 1"). A user typed a command-line option
// or a file key for each field; InUserTerms rewrites a message in those names, so that the
// message of bad input names what the user can change.

#include <string>
#include <utility>
#include <vector>

namespace specimen {

// Pairs of (field name in the library, name the user typed: "--radius-ratio", "safety_factor").
using FieldNames = std::vector<std::pair<std::string, std::string>>;

// `message` with every whole-word field name of `names` replaced by the user's name:
// "node_size_spread = 20 is not allowed: it must be in [1, radius_ratio = 10]" reads
// "--node-spread = 20 is not allowed: it must be in [1, --radius-ratio = 10]".
inline std::string InUserTerms(std::string message, const FieldNames& names) {
  auto identifier = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  };
  for (const auto& [field, user] : names) {
    for (size_t at = message.find(field); at != std::string::npos; at = message.find(field, at)) {
      const size_t end = at + field.size();
      const bool whole = (at == 0 || !identifier(message[at - 1])) &&
                         (end == message.size() || !identifier(message[end]));
      if (whole) {
        message.replace(at, field.size(), user);
        at += user.size();
      } else {
        at = end;
      }
    }
  }
  return message;
}

}  // namespace specimen
