#pragma once
// The packing file: a versioned, self-describing text format that round-trips
// bit-exactly (every double written with %.17g, read back with strtod). Example:
//
//   # specimen-packing 1
//   dimension 2
//   domain rectangle 0 0 0.1 0.1
//   created_by specimen 0.1.0
//   seed 42
//   contact_tolerance 0.01
//   # x y r
//   particles 2
//   0.025 0.05 0.025
//   0.075 0.05 0.025
//   # i j (0-based particle indices)
//   contacts 1
//   0 1
//
// The first line is the magic and the format version. Then header lines `key value` in
// any order, each key exactly once: dimension, domain (Domain::ToText), created_by (the
// rest of the line), seed (unsigned 64-bit), contact_tolerance. Then `particles N` and N
// lines `x y [z] r`, then `contacts M` and M lines `i j`. Lines starting with '#' (after
// the first) and blank lines are ignored. Nothing else may follow the contacts.

#include <iosfwd>
#include <string>

#include "generator/packing.h"

namespace specimen {

// The format version this build writes; the reader accepts exactly this version.
inline constexpr int kPackingFormatVersion = 1;

// Writes the packing in the format above. Throws InputError, before writing anything,
// if the packing could not be read back: centres and radii of different sizes, a
// non-finite number, a radius <= 0, a contact index out of range or joining a particle
// to itself, a negative or non-finite contact tolerance. Line breaks in created_by are
// written as spaces (the field is one line).
template <int Dim>
void WritePacking(const Packing<Dim>& packing, std::ostream& out);

// Reads a packing written by WritePacking. `source_name` (usually the path) names the
// input in error messages. Throws FileError naming the source, the line number and what
// was expected: wrong magic or version, a file of another dimension, missing, duplicate
// or unknown header keys, counts that do not match the lines, a malformed or non-finite
// number, a radius <= 0, a contact index out of range, i == j, a duplicate contact,
// anything after the contacts. Contacts are returned as (i < j) pairs, sorted, as the
// Packing expects; a file written by WritePacking reads back identical.
template <int Dim>
Packing<Dim> ReadPacking(std::istream& in, const std::string& source_name);

// The dimension (2 or 3) stated in the header of the packing file at `path`, to pick
// the template before loading. Reads only the header. Throws FileError as ReadPacking.
int ReadPackingDimension(const std::string& path);

// Writes `path` atomically (temporary file + rename): an error leaves no file behind.
// Throws InputError (naming `source` and the particle) for what a packing file can state but
// no specimen is: a centre outside the domain, a radius above half its smallest extent, two
// particles at one centre. The commands call it on every packing they read.
template <int Dim>
void CheckPackingGeometry(const Packing<Dim>& packing, const std::string& source);

template <int Dim>
void SavePacking(const Packing<Dim>& packing, const std::string& path);

// Opens and reads `path`; throws FileError if it cannot be opened or parsed.
template <int Dim>
Packing<Dim> LoadPacking(const std::string& path);

// A packing file read into memory once, for the commands: a pipe or FIFO (`--packing
// <(...)`) cannot be opened a second time, so the dimension and the packing come from this.
struct PackingFile {
  std::string path;
  std::string text;
  int dimension = 0;  // stated in the header
};
// Throws FileError as LoadPacking (a directory, a file that cannot be opened, a bad header).
PackingFile ReadPackingFile(const std::string& path);
// The same from text already read (`path` names it in messages).
PackingFile PackingFileFromText(const std::string& path, std::string text);
// Parses the text; throws FileError as ReadPacking, InputError if the dimension is not Dim.
template <int Dim>
Packing<Dim> ParsePackingFile(const PackingFile& file);

}  // namespace specimen
