#include "generator/packing_io.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <istream>
#include <iterator>
#include <sstream>
#include <map>
#include <ostream>
#include <utility>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/format.h"

namespace specimen {
namespace {

const char* const kMagic = "# specimen-packing";

// Header keys, in the order the writer puts them; the reader accepts any order.
const char* const kHeaderKeys[] = {"dimension", "domain", "created_by", "seed",
                                   "contact_tolerance"};

// At most this many elements are reserved from a count read in a file, so that a
// corrupt count cannot allocate gigabytes before the missing lines are noticed.
constexpr long long kMaximumReserve = 1 << 20;

std::string Trim(const std::string& text) {
  const size_t begin = text.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const size_t end = text.find_last_not_of(" \t\r");
  return text.substr(begin, end - begin + 1);
}

std::vector<std::string> SplitWords(const std::string& text) {
  std::vector<std::string> words;
  size_t position = 0;
  while (true) {
    const size_t begin = text.find_first_not_of(" \t\r", position);
    if (begin == std::string::npos) break;
    const size_t end = text.find_first_of(" \t\r", begin);
    words.push_back(text.substr(begin, end == std::string::npos ? std::string::npos : end - begin));
    if (end == std::string::npos) break;
    position = end;
  }
  return words;
}

// A short, printable quotation of a line for error messages (files may hold binary junk).
std::string Excerpt(const std::string& text) {
  constexpr size_t kLength = 60;
  std::string shown;
  for (char c : text.substr(0, kLength))
    shown += (static_cast<unsigned char>(c) < 32 || c == 127) ? '?' : c;
  if (text.size() > kLength) shown += "...";
  return "'" + shown + "'";
}

// Reads the file line by line, knows the current line number and turns problems into
// FileError messages that name the source and the line.
class LineReader {
 public:
  LineReader(std::istream& in, const std::string& source) : in_(in), source_(source) {}

  // The next line as it is (without the line break); false at the end of input.
  bool NextRaw(std::string* line) {
    if (!std::getline(in_, *line)) {
      if (in_.bad())
        throw FileError("packing file '" + source_ + "': reading failed after line " +
                        std::to_string(line_number_));
      return false;
    }
    ++line_number_;
    if (!line->empty() && line->back() == '\r') line->pop_back();  // CRLF files
    return true;
  }

  // The next line that is neither blank nor a comment, trimmed; false at the end.
  bool NextSignificant(std::string* line) {
    std::string raw;
    while (NextRaw(&raw)) {
      *line = Trim(raw);
      if (!line->empty() && (*line)[0] != '#') return true;
    }
    return false;
  }

  int line_number() const { return line_number_; }

  [[noreturn]] void FailAt(int line, const std::string& what) const {
    throw FileError("packing file '" + source_ + "', line " + std::to_string(line) + ": " + what);
  }
  [[noreturn]] void Fail(const std::string& what) const { FailAt(line_number_, what); }
  [[noreturn]] void FailAtEnd(const std::string& what) const {
    if (line_number_ == 0) throw FileError("packing file '" + source_ + "' is empty: " + what);
    throw FileError("packing file '" + source_ + "', end of file after line " +
                    std::to_string(line_number_) + ": " + what);
  }

 private:
  std::istream& in_;
  std::string source_;
  int line_number_ = 0;
};

// A finite double written in full; `what` names the field for the message.
double ParseFiniteDouble(const std::string& token, const std::string& what,
                         const LineReader& reader, int line) {
  double value = 0.0;
  if (!ParseDecimal(token, &value)) reader.FailAt(line, what + ": " + Excerpt(token) + " is not a finite decimal number");
  return value;
}

// A non-negative integer of digits only (strtoull alone would accept "-1" and wrap).
unsigned long long ParseUnsigned(const std::string& token, unsigned long long maximum,
                                 const std::string& what, const LineReader& reader, int line) {
  const bool digits_only =
      !token.empty() && token.find_first_not_of("0123456789") == std::string::npos;
  if (!digits_only)
    reader.FailAt(line, what + ": " + Excerpt(token) + " is not a non-negative integer");
  errno = 0;
  const unsigned long long value = std::strtoull(token.c_str(), nullptr, 10);
  if (errno == ERANGE || value > maximum)
    reader.FailAt(line, what + ": " + token + " is larger than the largest allowed, " +
                            std::to_string(maximum));
  return value;
}

// The header lines by key, with their line numbers, and the `particles N` line ending it.
struct Header {
  struct Field {
    std::string value;
    int line = 0;
  };
  std::map<std::string, Field> fields;
  int particles_line = 0;
  std::string particles_line_text;
};

// Line 1: the magic and a version this build reads.
void ReadMagic(LineReader& reader) {
  const std::string expected = std::string(kMagic) + " " + std::to_string(kPackingFormatVersion);
  std::string first;
  if (!reader.NextRaw(&first)) reader.FailAtEnd("a packing file starts with '" + expected + "'");
  first = Trim(first);
  if (first == expected) return;
  const std::string magic = kMagic;
  if (first.compare(0, magic.size(), magic) == 0) {
    const std::string version = Trim(first.substr(magic.size()));
    reader.Fail("packing format version " + Excerpt(version) +
                " is not supported; this build reads version " +
                std::to_string(kPackingFormatVersion) + " only (was the file written by a " +
                "newer specimen?)");
  }
  reader.Fail("not a specimen packing file: the first line must be '" + expected + "', found " +
              Excerpt(first));
}

// Checks line 1 and reads the header lines up to and including `particles N`.
Header ReadHeader(LineReader& reader) {
  ReadMagic(reader);
  Header header;
  std::string line;
  while (true) {
    if (!reader.NextSignificant(&line))
      reader.FailAtEnd("the file ends inside the header; expected 'particles <count>'");
    const size_t key_end = line.find_first_of(" \t");
    const std::string key = line.substr(0, key_end);
    const std::string value = key_end == std::string::npos ? "" : Trim(line.substr(key_end));
    if (key == "particles") {
      header.particles_line = reader.line_number();
      header.particles_line_text = line;
      break;
    }
    if (std::find(std::begin(kHeaderKeys), std::end(kHeaderKeys), key) == std::end(kHeaderKeys)) {
      std::string known;
      for (const char* k : kHeaderKeys) known += std::string(k) + ", ";
      reader.Fail("unknown header key " + Excerpt(key) + "; expected one of " + known +
                  "then 'particles <count>'");
    }
    const auto previous = header.fields.find(key);
    if (previous != header.fields.end())
      reader.Fail("header key '" + key + "' appears twice (first at line " +
                  std::to_string(previous->second.line) + ")");
    header.fields[key] = Header::Field{value, reader.line_number()};
  }
  for (const char* key : kHeaderKeys)
    if (header.fields.count(key) == 0)
      reader.FailAt(header.particles_line, "the header is missing '" + std::string(key) +
                                               "' (required before 'particles')");
  return header;
}

// The dimension field, checked to be 2 or 3.
int HeaderDimension(const Header& header, const LineReader& reader) {
  const Header::Field& field = header.fields.at("dimension");
  const std::string& value = field.value;
  if (value != "2" && value != "3")
    reader.FailAt(field.line, "dimension must be 2 or 3, found " + Excerpt(value));
  return value == "2" ? 2 : 3;
}

template <int Dim>
Domain<Dim> HeaderDomain(const Header& header, const LineReader& reader) {
  const Header::Field& field = header.fields.at("domain");
  const std::vector<std::string> words = SplitWords(field.value);
  if (words.empty()) reader.FailAt(field.line, "domain: the shape and its numbers are missing");
  // Checked here so that the message carries the line number, and because a polygon's
  // vertex count is converted to an integer by Domain::Parse.
  for (size_t k = 1; k < words.size(); ++k) {
    double value = 0.0;
    if (!ParseDecimal(words[k], &value))
      reader.FailAt(field.line, "domain: " + Excerpt(words[k]) + " is not a finite decimal number");
  }
  if (words[0] == "polygon" && words.size() > 1) {
    const double count = std::strtod(words[1].c_str(), nullptr);
    if (count < 3 || count != std::floor(count) || count > 1e7)
      reader.FailAt(field.line, "domain polygon: the vertex count " + Excerpt(words[1]) +
                                    " must be an integer >= 3");
  }
  try {
    return Domain<Dim>::Parse(field.value);
  } catch (const InputError& error) {
    reader.FailAt(field.line, std::string("domain: ") + error.what());
  }
}

// Parses the particle-count line `particles N`.
int ParticleCount(const Header& header, const LineReader& reader) {
  const std::vector<std::string> words = SplitWords(header.particles_line_text);
  if (words.size() != 2)
    reader.FailAt(header.particles_line,
                  "expected 'particles <count>', found " + Excerpt(header.particles_line_text));
  return static_cast<int>(
      ParseUnsigned(words[1], INT_MAX, "particle count", reader, header.particles_line));
}

template <int Dim>
const char* ParticleColumns() {
  return Dim == 2 ? "'x y r'" : "'x y z r'";
}

// Every condition the reader enforces, checked before writing so that a file written
// by WritePacking always reads back.
template <int Dim>
void RequireWritable(const Packing<Dim>& packing) {
  if (packing.centres.size() != packing.radii.size())
    throw InputError("cannot write packing: " + std::to_string(packing.centres.size()) +
                     " centres but " + std::to_string(packing.radii.size()) + " radii");
  if (packing.radii.size() > static_cast<size_t>(INT_MAX))
    throw InputError("cannot write packing: more than INT_MAX particles");
  const int count = packing.size();
  for (int i = 0; i < count; ++i) {
    if (!packing.centres[i].allFinite())
      throw InputError("cannot write packing: particle " + std::to_string(i) +
                       " has a non-finite centre");
    if (!std::isfinite(packing.radii[i]) || !(packing.radii[i] > 0.0))
      throw InputError("cannot write packing: particle " + std::to_string(i) + " has radius " +
                       ExactDouble(packing.radii[i]) + "; it must be finite and > 0");
  }
  if (!std::isfinite(packing.contact_tolerance) || packing.contact_tolerance < 0.0)
    throw InputError("cannot write packing: contact_tolerance = " +
                     ExactDouble(packing.contact_tolerance) + "; it must be finite and >= 0");
  std::vector<std::array<int, 2>> pairs;
  pairs.reserve(packing.contacts.size());
  for (const auto& contact : packing.contacts) {
    const int i = contact[0], j = contact[1];
    if (i < 0 || j < 0 || i >= count || j >= count || i == j)
      throw InputError("cannot write packing: contact (" + std::to_string(i) + ", " +
                       std::to_string(j) + ") is not a pair of two different particles among " +
                       std::to_string(count));
    pairs.push_back({std::min(i, j), std::max(i, j)});
  }
  std::sort(pairs.begin(), pairs.end());
  const auto duplicate = std::adjacent_find(pairs.begin(), pairs.end());
  if (duplicate != pairs.end())
    throw InputError("cannot write packing: contact (" + std::to_string((*duplicate)[0]) + ", " +
                     std::to_string((*duplicate)[1]) + ") is listed twice");
}

}  // namespace

template <int Dim>
void WritePacking(const Packing<Dim>& packing, std::ostream& out) {
  RequireWritable(packing);
  std::string created_by = packing.created_by;
  std::replace(created_by.begin(), created_by.end(), '\n', ' ');
  std::replace(created_by.begin(), created_by.end(), '\r', ' ');

  out << kMagic << ' ' << kPackingFormatVersion << '\n'
      << "dimension " << Dim << '\n'
      << "domain " << packing.domain.ToText() << '\n'
      << "created_by " << created_by << '\n'
      << "seed " << packing.seed << '\n'
      << "contact_tolerance " << ExactDouble(packing.contact_tolerance) << '\n';
  out << "# particle centre " << (Dim == 2 ? "x y" : "x y z") << " and radius r\n"
      << "particles " << packing.size() << '\n';
  for (int i = 0; i < packing.size(); ++i) {
    for (int k = 0; k < Dim; ++k) out << ExactDouble(packing.centres[i][k]) << ' ';
    out << ExactDouble(packing.radii[i]) << '\n';
  }
  out << "# contacts: 0-based particle indices i j\n"
      << "contacts " << packing.contacts.size() << '\n';
  for (const auto& contact : packing.contacts) out << contact[0] << ' ' << contact[1] << '\n';
}

template <int Dim>
Packing<Dim> ReadPacking(std::istream& in, const std::string& source_name) {
  LineReader reader(in, source_name);
  const Header header = ReadHeader(reader);

  // 1. Header: the dimension first, so that a 3D file read as 2D says so plainly.
  const int dimension = HeaderDimension(header, reader);
  if (dimension != Dim)
    reader.FailAt(header.fields.at("dimension").line,
                  "this is a " + std::to_string(dimension) + "D packing (dimension " +
                      std::to_string(dimension) + ") but a " + std::to_string(Dim) +
                      "D packing was expected");
  Packing<Dim> packing(HeaderDomain<Dim>(header, reader));
  packing.created_by = header.fields.at("created_by").value;
  {
    const Header::Field& field = header.fields.at("seed");
    if (SplitWords(field.value).size() != 1)
      reader.FailAt(field.line,
                    "seed: expected one unsigned integer, found " + Excerpt(field.value));
    static_assert(ULLONG_MAX >= UINT64_MAX, "seed is parsed as unsigned long long");
    packing.seed = ParseUnsigned(field.value, UINT64_MAX, "seed", reader, field.line);
  }
  {
    const Header::Field& field = header.fields.at("contact_tolerance");
    const std::vector<std::string> words = SplitWords(field.value);
    if (words.size() != 1)
      reader.FailAt(field.line,
                    "contact_tolerance: expected one number, found " + Excerpt(field.value));
    double value = 0.0;
    if (!ParseDecimal(words[0], &value) || value < 0.0)
      reader.FailAt(field.line,
                    "contact_tolerance: " + Excerpt(words[0]) + " is not a finite number >= 0");
    packing.contact_tolerance = value;
  }

  // 2. Particles.
  const int particle_count = ParticleCount(header, reader);
  packing.centres.reserve(
      static_cast<size_t>(std::min<long long>(particle_count, kMaximumReserve)));
  packing.radii.reserve(static_cast<size_t>(std::min<long long>(particle_count, kMaximumReserve)));
  std::string line;
  for (int i = 0; i < particle_count; ++i) {
    const std::string which = "particle " + std::to_string(i + 1) + " of " +
                              std::to_string(particle_count) + " (" + ParticleColumns<Dim>() + ")";
    if (!reader.NextSignificant(&line))
      reader.FailAtEnd("expected " + which + "; the particle count says " +
                       std::to_string(particle_count));
    const std::vector<std::string> words = SplitWords(line);
    if (words[0] == "contacts")
      reader.Fail("expected " + which + ", found " + Excerpt(line) + ": fewer particle lines " +
                  "than the particle count " + std::to_string(particle_count));
    if (words.size() != Dim + 1)
      reader.Fail(which + ": expected " + std::to_string(Dim + 1) + " numbers, found " +
                  std::to_string(words.size()));
    Vector<Dim> centre;
    for (int k = 0; k < Dim; ++k)
      centre[k] = ParseFiniteDouble(words[k], which, reader, reader.line_number());
    const double radius = ParseFiniteDouble(words[Dim], which, reader, reader.line_number());
    if (!(radius > 0.0)) reader.Fail(which + ": radius " + words[Dim] + " must be > 0");
    packing.centres.push_back(centre);
    packing.radii.push_back(radius);
  }

  // 3. Contacts, kept with their line numbers to report duplicates.
  if (!reader.NextSignificant(&line))
    reader.FailAtEnd("expected 'contacts <count>' after the " + std::to_string(particle_count) +
                     " particles");
  {
    const std::vector<std::string> words = SplitWords(line);
    if (words[0] != "contacts") {
      if (words.size() == Dim + 1)
        reader.Fail("expected 'contacts <count>', found " + Excerpt(line) +
                    ": more particle lines than the particle count " +
                    std::to_string(particle_count) + "?");
      reader.Fail("expected 'contacts <count>', found " + Excerpt(line));
    }
    if (words.size() != 2) reader.Fail("expected 'contacts <count>', found " + Excerpt(line));
  }
  const int contact_count = static_cast<int>(
      ParseUnsigned(SplitWords(line)[1], INT_MAX, "contact count", reader, reader.line_number()));
  struct NumberedContact {
    std::array<int, 2> pair;
    int line;
  };
  std::vector<NumberedContact> contacts;
  contacts.reserve(static_cast<size_t>(std::min<long long>(contact_count, kMaximumReserve)));
  for (int c = 0; c < contact_count; ++c) {
    const std::string which =
        "contact " + std::to_string(c + 1) + " of " + std::to_string(contact_count) + " ('i j')";
    if (!reader.NextSignificant(&line))
      reader.FailAtEnd("expected " + which + "; the contact count says " +
                       std::to_string(contact_count));
    const std::vector<std::string> words = SplitWords(line);
    if (words.size() != 2)
      reader.Fail(which + ": expected two particle indices, found " + Excerpt(line));
    int index[2];
    for (int k = 0; k < 2; ++k) {
      if (!words[k].empty() && words[k][0] == '-')
        reader.Fail(which + ": particle index " + Excerpt(words[k]) + " is negative");
      const unsigned long long value =
          ParseUnsigned(words[k], ULLONG_MAX, which, reader, reader.line_number());
      if (value >= static_cast<unsigned long long>(particle_count))
        reader.Fail(which + ": particle index " + words[k] + " is out of range; indices are " +
                    "0-based and there are " + std::to_string(particle_count) + " particles");
      index[k] = static_cast<int>(value);
    }
    if (index[0] == index[1])
      reader.Fail(which + ": joins particle " + words[0] + " to itself (i == j)");
    contacts.push_back(
        {{std::min(index[0], index[1]), std::max(index[0], index[1])}, reader.line_number()});
  }
  if (reader.NextSignificant(&line))
    reader.Fail("unexpected content after the last contact: " + Excerpt(line) +
                " (the contact count says " + std::to_string(contact_count) + ")");

  std::sort(contacts.begin(), contacts.end(),
            [](const NumberedContact& a, const NumberedContact& b) {
              return a.pair != b.pair ? a.pair < b.pair : a.line < b.line;
            });
  packing.contacts.reserve(contacts.size());
  for (size_t c = 0; c < contacts.size(); ++c) {
    if (c > 0 && contacts[c].pair == contacts[c - 1].pair)
      reader.FailAt(contacts[c].line, "duplicate contact " + std::to_string(contacts[c].pair[0]) +
                                          " " + std::to_string(contacts[c].pair[1]) +
                                          " (also at line " + std::to_string(contacts[c - 1].line) +
                                          ")");
    packing.contacts.push_back(contacts[c].pair);
  }
  return packing;
}

template <int Dim>
void CheckPackingGeometry(const Packing<Dim>& packing, const std::string& source) {
  const double extent = packing.domain.SmallestExtent();
  for (int i = 0; i < packing.size(); ++i) {
    const double inside = packing.domain.SignedDistance(packing.centres[i]);
    if (inside < -1e-9 * extent)
      throw InputError(source + ": particle " + std::to_string(i + 1) + " lies " + ExactDouble(-inside) +
                       " outside the domain " + packing.domain.ToShortText());
    if (packing.radii[i] > 0.5 * extent)
      throw InputError(source + ": particle " + std::to_string(i + 1) + " has radius " + ExactDouble(packing.radii[i]) +
                       ", larger than half the domain's smallest extent " + ExactDouble(extent));
  }
  // Two particles at one centre make every contact direction between them undefined.
  std::vector<int> order(packing.centres.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  auto key = [&](int i) {
    std::array<double, Dim> k{};
    for (int d = 0; d < Dim; ++d) k[d] = packing.centres[i][d];
    return k;
  };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return key(a) < key(b); });
  for (size_t k = 1; k < order.size(); ++k)
    if (key(order[k]) == key(order[k - 1]))
      throw InputError(source + ": particles " + std::to_string(std::min(order[k], order[k - 1]) + 1) + " and " +
                       std::to_string(std::max(order[k], order[k - 1]) + 1) + " have the same centre");
}

template void CheckPackingGeometry<2>(const Packing<2>&, const std::string&);
template void CheckPackingGeometry<3>(const Packing<3>&, const std::string&);

int ReadPackingDimension(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    throw FileError("packing file '" + path + "' is a directory");
  std::ifstream in(path);
  if (!in) throw FileError("cannot open packing file '" + path + "': " + std::strerror(errno));
  LineReader reader(in, path);
  const Header header = ReadHeader(reader);
  return HeaderDimension(header, reader);
}

template <int Dim>
void SavePacking(const Packing<Dim>& packing, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) { WritePacking(packing, out); });
}

template <int Dim>
Packing<Dim> LoadPacking(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    throw FileError("packing file '" + path + "' is a directory");
  std::ifstream in(path);
  if (!in) throw FileError("cannot open packing file '" + path + "': " + std::strerror(errno));
  return ReadPacking<Dim>(in, path);
}

PackingFile ReadPackingFile(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    throw FileError("packing file '" + path + "' is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError("cannot open packing file '" + path + "': " + std::strerror(errno));
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) throw FileError("packing file '" + path + "': reading failed: " + std::strerror(errno));
  return PackingFileFromText(path, std::move(text));
}

PackingFile PackingFileFromText(const std::string& path, std::string text) {
  PackingFile file;
  file.path = path;
  file.text = std::move(text);
  std::istringstream header_text(file.text);
  LineReader reader(header_text, path);
  file.dimension = HeaderDimension(ReadHeader(reader), reader);
  return file;
}

template <int Dim>
Packing<Dim> ParsePackingFile(const PackingFile& file) {
  if (file.dimension != Dim)
    throw InputError("packing file '" + file.path + "' is " + std::to_string(file.dimension) + "D, " +
                     std::to_string(Dim) + "D expected");
  std::istringstream in(file.text);
  return ReadPacking<Dim>(in, file.path);
}

template Packing<2> ParsePackingFile<2>(const PackingFile&);
template Packing<3> ParsePackingFile<3>(const PackingFile&);
template void WritePacking<2>(const Packing<2>&, std::ostream&);
template void WritePacking<3>(const Packing<3>&, std::ostream&);
template Packing<2> ReadPacking<2>(std::istream&, const std::string&);
template Packing<3> ReadPacking<3>(std::istream&, const std::string&);
template void SavePacking<2>(const Packing<2>&, const std::string&);
template void SavePacking<3>(const Packing<3>&, const std::string&);
template Packing<2> LoadPacking<2>(const std::string&);
template Packing<3> LoadPacking<3>(const std::string&);

}  // namespace specimen
