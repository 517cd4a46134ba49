#pragma once
// Stored micro-macro maps: the sweep points, the fitted surfaces with their fit
// errors, the descriptors of the packings they were built on and the code version, as one
// JSON file under data/maps/. A later calibration on a statistically equivalent packing
// with the same protocol reuses them instead of sweeping again.
//
// File name: maps_<dimension>d_<model>_<key>.json, the key a hash of everything the maps
// depend on (design, protocol, sweep specimens). A map is refused for a packing whose
// porosity, coordination or radius ratio differ (MapsMatchPacking): groups normalise by nc
// and (1 - e), but the shape of the maps still depends on the packing's structure.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "calibrate/dimensionless_groups.h"
#include "calibrate/map_set.h"
#include "calibrate/map_sweep.h"
#include "calibrate/surrogate.h"

namespace specimen {

// A measurement on the real (calibration) specimens stored with the maps: the transfer
// anchors measured when the maps were built (map_sweep.h TransferAnchorPoints), and the runs
// of later calibrations. Every calibration on an equivalent specimen corrects the surfaces by
// them (surrogate.h) before its first run. Groups as the sweep points'; an elastic run has
// no strengths (groups 0).
struct VerifiedPoint {
  MicroRatios ratios;
  PackingDescriptors specimen;  // the UCS specimen it was measured on
  double poisson_ratio = 0.0;
  double elastic_group = 0.0;      // 0: no elastic constants
  double compressive_group = 0.0;  // 0: no strengths
  double tensile_group = 0.0;
  std::string origin = "calibration";  // "anchor" or "calibration"

  // As the surrogate takes it: the groups back to E / kn and sigma / Rn on specimens with
  // these descriptors (the UCS specimen's for E and sigma_c, the Brazilian's for sigma_t).
  SurrogateMeasurement ToMeasurement(const PackingDescriptors& ucs, const PackingDescriptors& bts) const;

  nlohmann::json ToJson() const;
  static VerifiedPoint FromJson(const nlohmann::json& j);
};

struct StoredMaps {
  int dimension = 2;
  bool deformable = false;
  std::string code_version;   // of the program that built them
  std::string created_utc;    // ISO 8601
  std::string key;            // identity of design + protocol + sweep specimens
  nlohmann::json specimen;    // how the sweep specimens were made (free form, for the report)
  nlohmann::json protocol;    // the test protocol (rate, window, damping)
  PackingDescriptors ucs_descriptors;
  PackingDescriptors bts_descriptors;
  SweepDesign design;
  int max_total_degree = 2;
  std::vector<SweepPoint> points;
  MapSet maps;                // fitted from the points
  std::vector<VerifiedPoint> verified;  // verification runs on real specimens, newest last
  double sweep_seconds = 0.0; // wall time the sweep took when it was built

  nlohmann::json ToJson() const;
  // Throws InputError naming what is missing or malformed.
  static StoredMaps FromJson(const nlohmann::json& j);
};

// The time now, UTC, ISO 8601 (when a map was built).
std::string UtcNow();

// FNV-1a, 64 bit, as 16 hex digits: a stable file-name key (not a security hash).
std::string MapIdentityHash(const std::string& text);

// The key of a map: a hex hash of the canonical JSON of its identity.
std::string MapKey(int dimension, bool deformable, const SweepDesign& design,
                   const nlohmann::json& protocol, const nlohmann::json& specimen, int max_total_degree);
std::string MapFileName(int dimension, bool deformable, const std::string& key);
// The map file in `directory` for `key`: the one named by it, else the first file of that
// dimension and model whose identity (recomputed from its contents) gives it: a file stored
// under a key of an earlier program version is found all the same. Empty if none.
std::string FindStoredMapFile(const std::string& directory, int dimension, bool deformable, const std::string& key);

// Atomic write (FileError if the directory cannot be written).
void SaveStoredMaps(const StoredMaps& maps, const std::string& path);
// FileError if unreadable, InputError if not a map file (names the file and the problem).
StoredMaps LoadStoredMaps(const std::string& path);

// Whether maps built on `built_on` may be used for a packing described by `packing`:
// same dimension, porosity within 0.015 (absolute), coordination within 5 %, radius ratio
// within 25 %. Fills `why` with the first difference, naming both values.
bool MapsMatchPacking(const PackingDescriptors& built_on, const PackingDescriptors& packing, std::string* why);

}  // namespace specimen
