#include "calibrate/map_store.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"

namespace specimen {
namespace {

constexpr const char* kFormat = "specimen-maps 1";

// `value` rounded to `digits` significant digits.
double SignificantDigits(double value, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*g", digits, value);
  return std::strtod(text, nullptr);
}

}  // namespace

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

std::string MapIdentityHash(const std::string& text) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

nlohmann::json VerifiedPoint::ToJson() const {
  return {{"ratios", SweepPointRatiosToJson(ratios)},
          {"specimen", DescriptorsToJson(specimen)},
          {"poisson_ratio", poisson_ratio},
          {"elastic_group", elastic_group},
          {"compressive_group", compressive_group},
          {"tensile_group", tensile_group},
          {"origin", origin}};
}

SurrogateMeasurement VerifiedPoint::ToMeasurement(const PackingDescriptors& ucs, const PackingDescriptors& bts) const {
  SurrogateMeasurement m;
  m.ratios = ratios;
  if (elastic_group > 0.0) {
    m.youngs_per_stiffness = elastic_group * ucs.SolidCoordination() / ucs.CharacteristicRadius();
    m.poisson_ratio = poisson_ratio;
  }
  if (compressive_group > 0.0 && tensile_group > 0.0) {
    m.ucs_per_strength = compressive_group * ucs.SolidCoordination() / ucs.CharacteristicArea();
    m.tensile_per_strength = tensile_group * bts.SolidCoordination() / bts.CharacteristicArea();
  }
  return m;
}

VerifiedPoint VerifiedPoint::FromJson(const nlohmann::json& j) {
  VerifiedPoint v;
  v.ratios = SweepPointRatiosFromJson(j.at("ratios"));
  v.specimen = DescriptorsFromJson(j.at("specimen"));
  v.poisson_ratio = j.at("poisson_ratio").get<double>();
  v.elastic_group = j.at("elastic_group").get<double>();
  v.compressive_group = j.at("compressive_group").get<double>();
  v.tensile_group = j.at("tensile_group").get<double>();
  v.origin = j.value("origin", std::string("calibration"));
  return v;
}

nlohmann::json StoredMaps::ToJson() const {
  nlohmann::json j;
  j["format"] = kFormat;
  j["dimension"] = dimension;
  j["model"] = deformable ? "deformable" : "rigid";
  j["code_version"] = code_version;
  j["created_utc"] = created_utc;
  j["key"] = key;
  j["specimen"] = specimen;
  j["protocol"] = protocol;
  j["descriptors"] = {{"ucs", DescriptorsToJson(ucs_descriptors)}, {"bts", DescriptorsToJson(bts_descriptors)}};
  j["design"] = design.ToJson();
  j["max_total_degree"] = max_total_degree;
  j["sweep_seconds"] = sweep_seconds;
  j["points"] = nlohmann::json::array();
  for (const SweepPoint& p : points) j["points"].push_back(p.ToJson());
  j["verified"] = nlohmann::json::array();
  for (const VerifiedPoint& v : verified) j["verified"].push_back(v.ToJson());
  j["surfaces"] = {{"poisson_ratio", maps.poisson_ratio.ToJson()},
                   {"elastic_group", maps.elastic_group.ToJson()},
                   {"compressive_group", maps.compressive_group.ToJson()},
                   {"tensile_group", maps.tensile_group.ToJson()}};
  return j;
}

StoredMaps StoredMaps::FromJson(const nlohmann::json& j) {
  if (!j.is_object() || j.value("format", std::string()) != kFormat)
    throw InputError(std::string("not a map file (expected \"format\": \"") + kFormat + "\")");
  StoredMaps s;
  try {
    s.dimension = j.at("dimension").get<int>();
    s.deformable = j.at("model").get<std::string>() == "deformable";
    s.code_version = j.at("code_version").get<std::string>();
    s.created_utc = j.at("created_utc").get<std::string>();
    s.key = j.at("key").get<std::string>();
    s.specimen = j.at("specimen");
    s.protocol = j.at("protocol");
    s.ucs_descriptors = DescriptorsFromJson(j.at("descriptors").at("ucs"));
    s.bts_descriptors = DescriptorsFromJson(j.at("descriptors").at("bts"));
    s.design = SweepDesign::FromJson(j.at("design"));
    s.max_total_degree = j.at("max_total_degree").get<int>();
    s.sweep_seconds = j.value("sweep_seconds", 0.0);
    for (const auto& p : j.at("points")) s.points.push_back(SweepPoint::FromJson(p));
    if (j.contains("verified"))
      for (const auto& v : j.at("verified")) s.verified.push_back(VerifiedPoint::FromJson(v));
    const auto& surfaces = j.at("surfaces");
    s.maps.inputs = s.design.Inputs();
    s.maps.fixed = s.design.fixed;
    s.maps.poisson_ratio = ResponseSurface::FromJson(surfaces.at("poisson_ratio"));
    s.maps.elastic_group = ResponseSurface::FromJson(surfaces.at("elastic_group"));
    s.maps.compressive_group = ResponseSurface::FromJson(surfaces.at("compressive_group"));
    s.maps.tensile_group = ResponseSurface::FromJson(surfaces.at("tensile_group"));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("malformed map file: ") + e.what());
  }
  if (s.dimension != 2 && s.dimension != 3)
    throw InputError("map file: dimension = " + std::to_string(s.dimension) + ", allowed 2 or 3");
  if (s.maps.poisson_ratio.inputs() != static_cast<int>(s.maps.inputs.size()))
    throw InputError("map file: the surfaces do not match the design's inputs");
  // Surfaces stored by a program that fitted the strength groups linearly: the points are
  // the measurement, the surfaces only their fit, so they are fitted again as now.
  if (!s.maps.compressive_group.log_values() || !s.maps.tensile_group.log_values()) {
    MapSweep sweep;
    sweep.points = s.points;
    s.maps = FitMaps(sweep, s.design, s.max_total_degree);
  }
  return s;
}

std::string MapKey(int dimension, bool deformable, const SweepDesign& design, const nlohmann::json& protocol,
                   const nlohmann::json& specimen, int max_total_degree) {
  // The box enters with 6 significant digits: the DDEM bound on kn/(Ep l) comes from an
  // eigenvalue analysis whose last digits differ between builds and machines, and a
  // difference there must not make stored maps unfindable.
  SweepDesign rounded = design;
  for (SweepAxis& axis : rounded.axes) {
    axis.lower = SignificantDigits(axis.lower, 6);
    axis.upper = SignificantDigits(axis.upper, 6);
  }
  nlohmann::json identity = {{"format", kFormat},       {"dimension", dimension},
                             {"deformable", deformable}, {"design", rounded.ToJson()},
                             {"protocol", protocol},     {"specimen", specimen},
                             {"degree", max_total_degree}};
  return MapIdentityHash(identity.dump());
}

std::string MapFileName(int dimension, bool deformable, const std::string& key) {
  return "maps_" + std::to_string(dimension) + "d_" + (deformable ? "ddem" : "dem") + "_" + key + ".json";
}

std::string FindStoredMapFile(const std::string& directory, int dimension, bool deformable, const std::string& key) {
  namespace fs = std::filesystem;
  const fs::path named = fs::path(directory) / MapFileName(dimension, deformable, key);
  if (fs::exists(named)) return named.string();
  std::error_code error;
  if (!fs::is_directory(directory, error)) return {};
  const std::string prefix = MapFileName(dimension, deformable, "");
  std::vector<fs::path> candidates;
  for (const fs::directory_entry& e : fs::directory_iterator(directory, error)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && name.rfind(prefix.substr(0, prefix.size() - 5), 0) == 0 && e.path().extension() == ".json")
      candidates.push_back(e.path());
  }
  std::sort(candidates.begin(), candidates.end());  // the same choice on every machine
  for (const fs::path& p : candidates) {
    try {
      const StoredMaps m = LoadStoredMaps(p.string());
      if (m.dimension == dimension && m.deformable == deformable &&
          MapKey(m.dimension, m.deformable, m.design, m.protocol, m.specimen, m.max_total_degree) == key)
        return p.string();
    } catch (const std::exception&) {
      // Not a readable map file: not a candidate.
    }
  }
  return {};
}

void SaveStoredMaps(const StoredMaps& maps, const std::string& path) {
  const std::string text = maps.ToJson().dump(1);
  WriteFileAtomically(path, [&](std::ostream& out) { out << text << "\n"; });
}

StoredMaps LoadStoredMaps(const std::string& path) {
  if (std::filesystem::is_directory(path))
    throw FileError("the map file " + path + " is a directory, not a file");
  std::ifstream in(path);
  if (!in) throw FileError("cannot read the map file " + path);
  nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) throw InputError("the map file " + path + " is not valid JSON (truncated or not a map)");
  try {
    return StoredMaps::FromJson(j);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

bool MapsMatchPacking(const PackingDescriptors& built_on, const PackingDescriptors& packing, std::string* why) {
  std::ostringstream out;
  if (built_on.dimension != packing.dimension)
    out << "the maps are " << built_on.dimension << "D, the packing " << packing.dimension << "D";
  else if (std::abs(built_on.porosity - packing.porosity) > 0.015)
    out << "porosity " << packing.porosity << " differs from the maps' " << built_on.porosity
        << " by more than 0.015";
  else if (std::abs(built_on.coordination / packing.coordination - 1.0) > 0.05)
    out << "coordination number " << packing.coordination << " differs from the maps' "
        << built_on.coordination << " by more than 5 %";
  else if (std::abs(built_on.radius_ratio / packing.radius_ratio - 1.0) > 0.25)
    out << "radius ratio " << packing.radius_ratio << " differs from the maps' " << built_on.radius_ratio
        << " by more than 25 %";
  if (why) *why = out.str();
  return out.str().empty();
}

}  // namespace specimen
