// input-fuzz: a mutation fuzzer of the input readers (scene, material and stability-parameter
// TOML files, packing files), in process. Each iteration takes one of the seed files, applies
// a few random mutations (bytes, spans, tokens that break parsers: huge, tiny, non-finite and
// hexadecimal numbers, brackets, quotes, keys of the real files) and runs the reader and the
// checks a command runs before any work. An input must end in a result or in one of the typed
// errors (common/error.h) the commands turn into statuses 2, 3 and 4; any other exception, a
// crash or an iteration slower than --slow-seconds is a finding, written to --findings.
//
//   input-fuzz --seconds 3600 --findings out/fuzz --scene a.toml --material m.toml
//              --parameters p.toml --packing p.packing [--seed 1]
//
// tools/bench/input_fuzz.py builds the seed corpus, runs this and the command-level phase.

#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "calibrate/target_material.h"
#include "common/error.h"
#include "generator/packing_io.h"
#include "lab/lab_scene_file.h"
#include "stability/stability_parameters.h"

namespace specimen {
namespace {

enum class Reader { kScene, kMaterial, kParameters, kPacking };

struct Seed {
  Reader reader;
  std::string path;
  std::string text;
};

// Tokens that have broken parsers elsewhere: numbers at and past the limits of a double,
// forms strtod takes but the grammar refuses, TOML structure.
const std::vector<std::string> kTokens = {
    "0", "-0", "1e308", "1e309", "-1e308", "1e-320", "4.9e-324", "nan", "inf", "-inf", "0x10",
    "1e", ".", "-", "+", "--1", "1.5.2", "99999999999999999999", "-1", "2147483648",
    "9223372036854775808", "\"\"", "\"", "'", "[", "]", "[[", "]]", "{", "}", "=", ",", "#",
    "\n", "\r\n", "\t", " ", "\\", "\\u0000", "true", "false", "[1, 2]", "[]", "{a = 1}",
    "1979-05-27", "ucs", "brazilian", "biaxial", "lattice", "rectangle", "box 0 0 0 1 1 1",
    "polygon 3 0 0 1 0 0 1", "disc 0 0 1", "cylinder 0 0 0 1 1", "contacts", "particles",
    "dimension 2", "dimension 3", "dimension 4"};

std::string Mutate(std::string text, std::mt19937_64& rng, const std::vector<std::string>& words) {
  std::uniform_int_distribution<int> how(0, 7);
  const int count = 1 + static_cast<int>(rng() % 4);
  for (int m = 0; m < count; ++m) {
    const size_t n = text.size();
    auto at = [&](size_t limit) { return limit == 0 ? 0 : static_cast<size_t>(rng() % (limit + 1)); };
    switch (how(rng)) {
      case 0:  // flip a byte
        if (n > 0) text[at(n - 1)] = static_cast<char>(rng() % 256);
        break;
      case 1: {  // delete a span
        const size_t a = at(n), len = std::min(n - a, static_cast<size_t>(1 + rng() % 40));
        text.erase(a, len);
        break;
      }
      case 2: {  // duplicate a span
        const size_t a = at(n), len = std::min(n - a, static_cast<size_t>(1 + rng() % 200));
        text.insert(at(n), text.substr(a, len));
        break;
      }
      case 3:  // insert a token
        text.insert(at(n), kTokens[rng() % kTokens.size()]);
        break;
      case 4: {  // replace a number with a token
        const size_t a = text.find_first_of("0123456789", at(n));
        if (a == std::string::npos) break;
        const size_t b = text.find_first_not_of("0123456789.eE+-", a);
        text.replace(a, (b == std::string::npos ? n : b) - a, kTokens[rng() % kTokens.size()]);
        break;
      }
      case 5:  // insert a word of the seed files (keys, table names)
        if (!words.empty()) text.insert(at(n), words[rng() % words.size()]);
        break;
      case 6: {  // delete a line
        const size_t a = text.rfind('\n', at(n));
        const size_t start = a == std::string::npos ? 0 : a + 1;
        const size_t end = text.find('\n', start);
        text.erase(start, end == std::string::npos ? std::string::npos : end - start + 1);
        break;
      }
      default: {  // swap two lines' order: a key before its table, contacts before particles
        const size_t a = text.find('\n', at(n)), b = text.find('\n', at(n));
        if (a == std::string::npos || b == std::string::npos || a == b) break;
        const size_t first = std::min(a, b) + 1, second = std::max(a, b) + 1;
        const size_t end = text.find('\n', second);
        if (first >= second) break;
        const std::string line = text.substr(second, (end == std::string::npos ? text.size() : end + 1) - second);
        text.erase(second, line.size());
        text.insert(first, line);
      }
    }
  }
  return text;
}

// The reader and the checks a command makes before any work.
void Read(Reader reader, const std::string& text, const std::string& source) {
  std::string error;
  switch (reader) {
    case Reader::kScene: {
      LabScene scene = ParseLabScene(text, source);
      if (!scene.test.IsValid(&error)) throw InputError(error);
      if (!scene.lattice && !scene.material.IsValid(&error)) throw InputError(error);
      break;
    }
    case Reader::kMaterial: {
      const TargetMaterial material = ParseTargetMaterial(text, source);
      if (!material.IsValid(&error)) throw InputError(error);
      break;
    }
    case Reader::kParameters:
      ParseStabilityParameters(text, source);
      break;
    case Reader::kPacking: {
      // As the commands read it: the header's dimension, then the whole file, then the geometry.
      const PackingFile file = PackingFileFromText(source, text);
      if (file.dimension == 3)
        CheckPackingGeometry<3>(ParsePackingFile<3>(file), source);
      else
        CheckPackingGeometry<2>(ParsePackingFile<2>(file), source);
      break;
    }
  }
}

// The input in flight, written out if the process crashes (best effort: write(2) only).
std::string g_crash_path;
const std::string* g_current = nullptr;
void OnCrash(int signal) {
  if (g_current) {
    const int fd = ::open(g_crash_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      (void)!::write(fd, g_current->data(), g_current->size());
      ::close(fd);
    }
  }
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

std::vector<std::string> WordsOf(const std::vector<Seed>& seeds) {
  std::vector<std::string> words;
  for (const Seed& s : seeds) {
    std::istringstream in(s.text);
    std::string w;
    while (in >> w)
      if (w.size() < 40 && w.find_first_not_of("abcdefghijklmnopqrstuvwxyz_[].") == std::string::npos) words.push_back(w);
  }
  return words;
}

}  // namespace
}  // namespace specimen

int main(int argc, char** argv) {
  using namespace specimen;
  CLI::App app{"input-fuzz: mutation fuzzer of the input readers"};
  double seconds = 60.0, slow_seconds = 5.0;
  std::uint64_t seed = 1;
  std::string findings = "fuzz-findings";
  std::vector<std::string> scenes, materials, parameters, packings;
  app.add_option("--seconds", seconds, "how long to run");
  app.add_option("--slow-seconds", slow_seconds, "an iteration slower than this is a finding (a hang)");
  app.add_option("--seed", seed, "random seed");
  app.add_option("--findings", findings, "directory for the inputs that failed")->required();
  app.add_option("--scene", scenes, "seed scene files");
  app.add_option("--material", materials, "seed material files");
  app.add_option("--parameters", parameters, "seed stability-parameter files");
  app.add_option("--packing", packings, "seed packing files");
  CLI11_PARSE(app, argc, argv);

  std::vector<Seed> seeds;
  auto add = [&](Reader r, const std::vector<std::string>& paths) {
    for (const std::string& p : paths) {
      std::ifstream in(p, std::ios::binary);
      if (!in) {
        std::cerr << "input-fuzz: cannot read " << p << "\n";
        std::exit(3);
      }
      std::ostringstream text;
      text << in.rdbuf();
      seeds.push_back({r, p, text.str()});
    }
  };
  add(Reader::kScene, scenes);
  add(Reader::kMaterial, materials);
  add(Reader::kParameters, parameters);
  add(Reader::kPacking, packings);
  if (seeds.empty()) {
    std::cerr << "input-fuzz: give at least one seed file\n";
    return 2;
  }
  std::filesystem::create_directories(findings);
  g_crash_path = findings + "/crash.input";
  std::signal(SIGSEGV, OnCrash);
  std::signal(SIGABRT, OnCrash);
  std::signal(SIGFPE, OnCrash);
  std::signal(SIGBUS, OnCrash);

  const std::vector<std::string> words = WordsOf(seeds);
  std::mt19937_64 rng(seed);
  const char* names[] = {"scene", "material", "parameters", "packing"};
  struct Counts {
    long runs = 0, accepted = 0, input = 0, file = 0, computation = 0, other = 0, slow = 0;
    double slowest_s = 0.0;
  };
  Counts counts[4];
  const auto start = std::chrono::steady_clock::now();
  long findings_written = 0;
  for (long iteration = 0;; ++iteration) {
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= seconds) break;
    const Seed& s = seeds[rng() % seeds.size()];
    const std::string input = Mutate(s.text, rng, words);
    g_current = &input;
    Counts& c = counts[static_cast<int>(s.reader)];
    ++c.runs;
    const auto t0 = std::chrono::steady_clock::now();
    std::string other;
    try {
      Read(s.reader, input, s.path);
      ++c.accepted;
    } catch (const InputError&) {
      ++c.input;
    } catch (const FileError&) {
      ++c.file;
    } catch (const ComputationError&) {
      ++c.computation;
    } catch (const std::exception& e) {
      ++c.other;
      other = e.what();
    }
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    c.slowest_s = std::max(c.slowest_s, dt);
    if (dt > slow_seconds) ++c.slow;
    if ((!other.empty() || dt > slow_seconds) && findings_written < 100) {
      const std::string base = findings + "/" + names[static_cast<int>(s.reader)] + "_" + std::to_string(iteration);
      std::ofstream(base + ".input", std::ios::binary) << input;
      std::ofstream(base + ".why") << (other.empty() ? "slow: " + std::to_string(dt) + " s" : "exception: " + other)
                                   << "\n";
      ++findings_written;
    }
  }
  g_current = nullptr;
  std::printf("| reader | inputs | accepted | bad input (2) | file error (3) | computation (4) | other exception | slower than %.0f s | slowest |\n",
              slow_seconds);
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  long bad = 0;
  for (int r = 0; r < 4; ++r) {
    const Counts& c = counts[r];
    if (c.runs == 0) continue;
    std::printf("| %s | %ld | %ld | %ld | %ld | %ld | %ld | %ld | %.3f s |\n", names[r], c.runs, c.accepted, c.input,
                c.file, c.computation, c.other, c.slow, c.slowest_s);
    bad += c.other + c.slow;
  }
  return bad == 0 ? 0 : 1;
}
