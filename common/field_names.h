#pragma once
// The library validates its option structs and names their fields in the messages
// ("radius_ratio = 0.5 is not allowed: it must be >= 1"). A user typed a command-line option
// or a file key for each field; InUserTerms rewrites a message in those names, so that the
// message of bad input names what the user can change.

#include <algorithm>
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

// For a key that is missing: the keys present that are within two edits of it (a typo:
// "normal_stifness" for "normal_stiffness"), as " (the table has 'normal_stifness':
// misspelled?)", or "" when none is.
inline std::string MisspeltKeys(const std::string& key, const std::vector<std::string>& present) {
  auto distance = [](const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
      size_t diagonal = row[0];
      row[0] = i;
      for (size_t j = 1; j <= b.size(); ++j) {
        const size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
        diagonal = up;
      }
    }
    return row[b.size()];
  };
  std::string found;
  for (const std::string& p : present)
    if (p != key && distance(p, key) <= 2) found += (found.empty() ? "'" : ", '") + p + "'";
  return found.empty() ? "" : " (the table has " + found + ": misspelled?)";
}

}  // namespace specimen
