#include "calibrate/map_sweep.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "common/error.h"
#include "calibrate/intact_elastic.h"
#include "generator/metrics.h"
#include "common/format.h"
#include "common/ranks.h"

namespace specimen {
namespace {

MicroRatio RatioFromName(const std::string& name) {
  for (MicroRatio r : {MicroRatio::kStiffnessRatio, MicroRatio::kStrengthRatio, MicroRatio::kFriction,
                       MicroRatio::kParticleCompliance, MicroRatio::kParticlePoisson})
    if (MicroRatioName(r) == name) return r;
  throw InputError("unknown micro ratio '" + name + "' in a sweep design");
}

}  // namespace

nlohmann::json SweepPointRatiosToJson(const MicroRatios& r) {
  nlohmann::json j = {{"kt_over_kn", r.tangential_to_normal_stiffness},
                      {"rt_over_rn", r.shear_to_tensile_strength},
                      {"friction", r.friction_coefficient},
                      {"kn_over_ep_l", r.normal_stiffness_to_particle},
                      {"particle_poisson_ratio", r.particle_poisson_ratio}};
  // Written only when bonds reach beyond the contacts: maps without it keep their keys.
  if (r.bond_range != 1.0) j["bond_range"] = r.bond_range;
  return j;
}

MicroRatios SweepPointRatiosFromJson(const nlohmann::json& j) {
  MicroRatios r;
  r.tangential_to_normal_stiffness = j.at("kt_over_kn").get<double>();
  r.shear_to_tensile_strength = j.at("rt_over_rn").get<double>();
  r.friction_coefficient = j.at("friction").get<double>();
  r.normal_stiffness_to_particle = j.at("kn_over_ep_l").get<double>();
  r.particle_poisson_ratio = j.at("particle_poisson_ratio").get<double>();
  r.bond_range = j.value("bond_range", 1.0);
  return r;
}

namespace {

// The identity of a sweep in the journal: a point is reused only by the same points and
// protocol.
std::string SweepKey(const std::vector<MicroRatios>& grid, const MapSweepOptions& options) {
  nlohmann::json key;
  key["points"] = nlohmann::json::array();
  for (const MicroRatios& r : grid) key["points"].push_back(SweepPointRatiosToJson(r));
  key["elastic"] = "intact linear portion";
  key["kn"] = options.normal_stiffness_n_per_m;
  key["rn"] = options.bond_tensile_strength_n;
  key["rho"] = options.density_kg_per_m3;
  key["rate"] = options.test.loading_rate_group;
  key["window"] = {options.test.modulus_window_low, options.test.modulus_window_high};
  return key.dump();
}

// Appends one line and makes it durable before returning (a kill loses nothing written).
void AppendJournalLine(const std::string& path, const std::string& line) {
  FILE* file = std::fopen(path.c_str(), "a");
  if (!file) throw FileError("cannot append to the sweep journal " + path);
  const bool ok = std::fputs((line + "\n").c_str(), file) >= 0 && std::fflush(file) == 0 &&
                  ::fsync(fileno(file)) == 0;
  std::fclose(file);
  if (!ok) throw FileError("cannot write the sweep journal " + path);
}

// Finished points of the same design; a torn last line (killed mid-write) is ignored.
std::vector<SweepPoint> ReadJournal(const std::string& path, const std::string& key) {
  std::vector<SweepPoint> points;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    nlohmann::json j = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded() || !j.is_object() || j.value("design", std::string()) != key) continue;
    try {
      points.push_back(SweepPoint::FromJson(j.at("point")));
    } catch (const std::exception&) {
      continue;  // an incomplete record: run the point again
    }
  }
  return points;
}

template <int Dim>
PackingDescriptors Describe(const Packing<Dim>& packing) {
  return DescribePacking<Dim>(ComputePackingMetrics<Dim>(packing));
}

}  // namespace

double SweepAxis::At(double fraction) const {
  if (geometric) return lower * std::pow(upper / lower, fraction);
  return lower + (upper - lower) * fraction;
}

std::vector<MicroRatios> SweepDesign::Points() const {
  std::vector<MicroRatios> points(1, fixed);
  for (const SweepAxis& axis : axes) {
    std::vector<MicroRatios> next;
    for (const MicroRatios& base : points)
      for (int level = 0; level < axis.levels; ++level) {
        MicroRatios r = base;
        SetRatioValue(&r, axis.ratio, axis.At(static_cast<double>(level) / (axis.levels - 1)));
        next.push_back(r);
      }
    points = std::move(next);
  }
  return points;
}

std::vector<MicroRatio> SweepDesign::Inputs() const {
  std::vector<MicroRatio> inputs;
  for (const SweepAxis& axis : axes) inputs.push_back(axis.ratio);
  return inputs;
}

bool SweepDesign::IsValid(std::string* error) const {
  std::ostringstream out;
  std::set<MicroRatio> seen;
  if (axes.empty()) out << "sweep design: no axis (at least one micro ratio must vary)";
  for (const SweepAxis& a : axes) {
    if (!out.str().empty()) break;
    const std::string name = MicroRatioName(a.ratio);
    if (!seen.insert(a.ratio).second) out << "sweep design: axis " << name << " appears twice";
    else if (a.levels < 2 || a.levels > 20)
      out << "sweep design: levels of " << name << " = " << a.levels << ", allowed 2 to 20";
    else if (!(a.lower < a.upper))
      out << "sweep design: range of " << name << " [" << a.lower << ", " << a.upper
          << "] is empty, lower must be below upper";
    else if (a.ratio == MicroRatio::kStiffnessRatio && !(a.lower >= 0.0))
      out << "sweep design: kt/kn lower = " << a.lower << ", allowed >= 0";
    else if (a.ratio == MicroRatio::kStrengthRatio && !(a.lower > 0.0))
      out << "sweep design: Rt/Rn lower = " << a.lower << ", allowed > 0";
    else if (a.geometric && !(a.lower > 0.0))
      out << "sweep design: geometric axis " << name << " lower = " << a.lower << ", allowed > 0";
    else if (a.ratio == MicroRatio::kFriction && !(a.lower >= 0.0))
      out << "sweep design: mu lower = " << a.lower << ", allowed >= 0";
    else if (a.ratio == MicroRatio::kParticleCompliance && !(a.lower >= 0.0))
      out << "sweep design: kn/(Ep l) lower = " << a.lower << ", allowed >= 0";
    else if (a.ratio == MicroRatio::kParticlePoisson && !(a.lower > -1.0 && a.upper < 0.5))
      out << "sweep design: nu_p range [" << a.lower << ", " << a.upper << "], allowed (-1, 0.5)";
  }
  if (out.str().empty() && Points().size() > 400)
    out << "sweep design: " << Points().size() << " points, allowed at most 400";
  if (error) *error = out.str();
  return out.str().empty();
}

std::vector<MicroRatios> TransferAnchorPoints(const SweepDesign& design, int levels) {
  const int k = static_cast<int>(design.axes.size());
  std::vector<MicroRatios> points;
  auto at = [&](const std::vector<double>& fractions) {
    MicroRatios r = design.fixed;
    for (int a = 0; a < k; ++a) SetRatioValue(&r, design.axes[a].ratio, design.axes[a].At(fractions[a]));
    return r;
  };
  for (int corner = 0; corner < (1 << k); ++corner) {
    int sign_product = 1;
    std::vector<double> f(k);
    for (int a = 0; a < k; ++a) {
      const bool high = (corner >> a) & 1;
      sign_product *= high ? 1 : -1;
      f[a] = high ? 0.75 : 0.25;
    }
    if (k >= 3 && sign_product < 0) continue;  // the half fraction
    points.push_back(at(f));
    if (points.size() == 4) break;
  }
  if (levels < 3 || k == 0) return points;
  // The three-level design: every pair of levels 0, 1/2, 1 of the first two axes once; a
  // third axis at (i + j) mod 3 (a Latin square: every pair of levels of any two axes once).
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < (k >= 2 ? 3 : 1); ++j) {
      std::vector<double> f(k, 0.5);
      f[0] = 0.5 * i;
      if (k >= 2) f[1] = 0.5 * j;
      if (k >= 3) f[2] = 0.5 * ((i + j) % 3);
      points.push_back(at(f));
    }
  return points;
}

nlohmann::json SweepDesign::ToJson() const {
  nlohmann::json j;
  j["axes"] = nlohmann::json::array();
  for (const SweepAxis& a : axes)
    j["axes"].push_back({{"ratio", MicroRatioName(a.ratio)}, {"lower", a.lower}, {"upper", a.upper},
                         {"levels", a.levels}, {"geometric", a.geometric}});
  j["fixed"] = SweepPointRatiosToJson(fixed);
  return j;
}

SweepDesign SweepDesign::FromJson(const nlohmann::json& j) {
  SweepDesign d;
  for (const auto& a : j.at("axes"))
    d.axes.push_back({RatioFromName(a.at("ratio").get<std::string>()), a.at("lower").get<double>(),
                      a.at("upper").get<double>(), a.at("levels").get<int>(), a.value("geometric", false)});
  d.fixed = SweepPointRatiosFromJson(j.at("fixed"));
  return d;
}

SweepDesign DefaultSweepDesign(bool deformable, double particle_poisson_ratio,
                               double largest_particle_compliance, double friction_coefficient) {
  SweepDesign d;
  d.fixed.friction_coefficient = friction_coefficient;
  d.fixed.shear_to_tensile_strength = 10.0;
  d.fixed.tangential_to_normal_stiffness = 0.25;
  if (!deformable) {
    d.axes = {{MicroRatio::kStiffnessRatio, 0.15, 0.9, 4}, {MicroRatio::kStrengthRatio, 1.0, 10.0, 3, true}};
    return d;
  }
  d.fixed.particle_poisson_ratio = particle_poisson_ratio;
  d.axes = {{MicroRatio::kStiffnessRatio, 0.15, 0.6, 3},
            {MicroRatio::kParticleCompliance, 0.0, largest_particle_compliance, 3},
            {MicroRatio::kStrengthRatio, 1.0, 10.0, 3, true}};
  return d;
}

nlohmann::json SweepPoint::ToJson() const {
  return {{"index", index},
          {"ratios", SweepPointRatiosToJson(ratios)},
          {"ok", ok},
          {"failure", failure},
          {"youngs_modulus_pa", youngs_modulus_pa},
          {"poisson_ratio", poisson_ratio},
          {"ucs_pa", ucs_pa},
          {"tensile_strength_pa", tensile_strength_pa},
          {"ucs_peak_reached", ucs_peak_reached},
          {"bts_peak_reached", bts_peak_reached},
          {"elastic_group", elastic_group},
          {"compressive_group", compressive_group},
          {"tensile_group", tensile_group},
          {"seconds", seconds}};
}

SweepPoint SweepPoint::FromJson(const nlohmann::json& j) {
  SweepPoint p;
  p.index = j.at("index").get<int>();
  p.ratios = SweepPointRatiosFromJson(j.at("ratios"));
  p.ok = j.at("ok").get<bool>();
  p.failure = j.at("failure").get<std::string>();
  p.youngs_modulus_pa = j.at("youngs_modulus_pa").get<double>();
  p.poisson_ratio = j.at("poisson_ratio").get<double>();
  p.ucs_pa = j.at("ucs_pa").get<double>();
  p.tensile_strength_pa = j.at("tensile_strength_pa").get<double>();
  p.ucs_peak_reached = j.at("ucs_peak_reached").get<bool>();
  p.bts_peak_reached = j.at("bts_peak_reached").get<bool>();
  p.elastic_group = j.at("elastic_group").get<double>();
  p.compressive_group = j.at("compressive_group").get<double>();
  p.tensile_group = j.at("tensile_group").get<double>();
  p.seconds = j.at("seconds").get<double>();
  return p;
}

bool MapSweepOptions::IsValid(std::string* error) const {
  std::ostringstream out;
  if (!(normal_stiffness_n_per_m > 0.0 && std::isfinite(normal_stiffness_n_per_m)))
    out << "sweep normal_stiffness = " << normal_stiffness_n_per_m << ", allowed > 0";
  else if (!(bond_tensile_strength_n > 0.0 && std::isfinite(bond_tensile_strength_n)))
    out << "sweep bond_tensile_strength = " << bond_tensile_strength_n << ", allowed > 0";
  else if (!(density_kg_per_m3 > 0.0 && std::isfinite(density_kg_per_m3)))
    out << "sweep density = " << density_kg_per_m3 << ", allowed > 0";
  else if (workers < 1 || workers > 256)
    out << "sweep workers = " << workers << ", allowed 1 to 256";
  std::string test_error;
  if (out.str().empty() && !test.IsValid(&test_error)) out << test_error;
  if (error) *error = out.str();
  return out.str().empty();
}

LabTestOptions StrengthTestProtocol(LabTestOptions protocol) {
  protocol.num_threads = 1;
  protocol.check_quasi_static = false;
  if (protocol.strain_limit == 0.0) protocol.strain_limit = 0.05;
  return protocol;
}

MaterialParameters MaterialAt(const MicroRatios& r, double kn, double rn, double density,
                              PlaneModel plane_model, double group_length_m) {
  MaterialParameters m;
  m.normal_stiffness_n_per_m = kn;
  m.tangential_stiffness_n_per_m = r.tangential_to_normal_stiffness * kn;
  m.bond_tensile_strength_n = rn;
  m.bond_shear_strength_n = r.shear_to_tensile_strength * rn;
  m.friction_coefficient = r.friction_coefficient;
  m.bond_range = r.bond_range;
  m.density_kg_per_m3 = density;
  m.plane_model = plane_model;
  if (r.normal_stiffness_to_particle > 0.0) {
    m.particle_youngs_modulus_pa = kn / (r.normal_stiffness_to_particle * group_length_m);
    m.particle_poisson_ratio = r.particle_poisson_ratio;
  }
  return m;
}

template <int Dim>
MapSweep RunMapSweep(const Packing<Dim>& ucs_packing, const Packing<Dim>& bts_packing,
                     const SweepDesign& design, const MapSweepOptions& options) {
  std::string error;
  if (!design.IsValid(&error)) throw InputError(error);
  return RunSweepPoints<Dim>(ucs_packing, bts_packing, design.Points(), options);
}

namespace {

// The journal a rank appends to: rank 0 the sweep's own (the file of a run without MPI),
// rank r > 0 "<journal>.rank<r>" beside it, so that two ranks never write one file.
std::string RankJournalPath(const std::string& journal, int rank) {
  return rank == 0 ? journal : journal + ".rank" + std::to_string(rank);
}

// The sweep's journal and every rank journal beside it (of this run, or of a run with more
// ranks that was killed).
std::vector<std::string> JournalFiles(const std::string& journal) {
  namespace fs = std::filesystem;
  std::vector<std::string> files = {journal};
  const fs::path path(journal);
  const fs::path directory = path.has_parent_path() ? path.parent_path() : fs::path(".");
  const std::string prefix = path.filename().string() + ".rank";
  std::error_code error;
  std::vector<std::string> ranks;
  for (const auto& entry : fs::directory_iterator(directory, error)) {
    const std::string name = entry.path().filename().string();
    if (name.size() > prefix.size() && name.compare(0, prefix.size(), prefix) == 0 &&
        name.find_first_not_of("0123456789", prefix.size()) == std::string::npos)
      ranks.push_back(entry.path().string());
  }
  std::sort(ranks.begin(), ranks.end());  // the same order on every machine
  files.insert(files.end(), ranks.begin(), ranks.end());
  return files;
}

// Opens this rank's journal for appending (a FileError now rather than after the first
// point); a torn last line (a kill mid-write) is ended, so that the next line stays whole.
void PrepareJournal(const std::string& path) {
  {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (in && in.tellg() > 0) {
      in.seekg(-1, std::ios::end);
      char last = '\n';
      in.get(last);
      in.close();
      if (last != '\n') AppendJournalLine(path, "");
    }
  }
  std::ofstream probe(path, std::ios::app);
  if (!probe) throw FileError("cannot write the sweep journal " + path);
}

// Test hook of the resume test (tests/tools/mpi_sweep_test.py): "RANK:COUNT" makes that rank
// end at once, as a killed process would, after journaling COUNT points.
int ExitAfterPoints(int rank) {
  const char* hook = std::getenv("SPECIMEN_TEST_SWEEP_EXIT");
  int hook_rank = -1, count = 0;
  if (!hook || std::sscanf(hook, "%d:%d", &hook_rank, &count) != 2 || hook_rank != rank) return -1;
  return count;
}

// A failure that stops the sweep, carried between ranks as data: every rank joins the
// exchange of results and then throws the same error.
struct SweepStop {
  std::string message;  // empty: none
  bool file = false;    // FileError, else the sweep's own failure
};

}  // namespace

template <int Dim>
MapSweep RunSweepPoints(const Packing<Dim>& ucs_packing, const Packing<Dim>& bts_packing,
                        const std::vector<MicroRatios>& grid, const MapSweepOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  if (grid.empty()) throw InputError("map sweep: no point to run");
  const auto start = std::chrono::steady_clock::now();
  const int rank = Rank(), ranks = RankCount();

  MapSweep sweep;
  sweep.ucs_descriptors = Describe(ucs_packing);
  sweep.bts_descriptors = Describe(bts_packing);
  const double group_length = Dim == 2 ? 1.0 : sweep.ucs_descriptors.mean_radius;
  sweep.points.resize(grid.size());
  std::vector<bool> done(grid.size(), false);

  // Resume: rank 0 reads the journal and the rank journals, and sends what it found to every
  // rank, so that every rank splits the same pending list (whatever each one's view of the
  // file system).
  const std::string key = SweepKey(grid, options);
  const bool journaled = !options.journal_path.empty();
  if (journaled) {
    nlohmann::json resumed = nlohmann::json::array();
    if (rank == 0)
      for (const std::string& file : JournalFiles(options.journal_path))
        for (const SweepPoint& p : ReadJournal(file, key)) resumed.push_back(p.ToJson());
    resumed = nlohmann::json::parse(Broadcast(resumed.dump()));
    for (const nlohmann::json& j : resumed) {
      const SweepPoint p = SweepPoint::FromJson(j);
      if (p.index >= 0 && p.index < static_cast<int>(grid.size()) && !done[p.index]) {
        sweep.points[p.index] = p;
        done[p.index] = true;
        ++sweep.resumed_points;
      }
    }
  }
  const std::string journal = journaled ? RankJournalPath(options.journal_path, rank) : std::string();
  SweepStop stop;
  try {
    if (journaled) PrepareJournal(journal);
  } catch (const FileError& e) {
    stop = {std::string(e.what()) + (ranks > 1 ? " (on rank " + std::to_string(rank) + ")" : ""), true};
  }

  // Point k of the pending list runs on rank k % N: known in advance, the same on every rank,
  // and each point's result depends only on the point (one solver thread per test), so the
  // sweep is the same whatever N.
  std::vector<int> pending, mine;
  for (int i = 0; i < static_cast<int>(grid.size()); ++i)
    if (!done[i]) pending.push_back(i);
  for (size_t k = 0; k < pending.size(); ++k)
    if (static_cast<int>(k % ranks) == rank) mine.push_back(pending[k]);

  std::atomic<int> next{0};
  std::mutex mutex;  // journal, the finished queue and the first error of this rank
  std::condition_variable finished_signal;
  std::vector<int> finished_queue;  // index * 2 + ok, for the main thread
  int running_workers = 0;
  int journaled_here = 0;
  const int exit_after = ExitAfterPoints(rank);
  const int total = static_cast<int>(grid.size());
  if (options.progress && !pending.empty() && rank == 0)
    options.progress(static_cast<double>(sweep.resumed_points) / total,
                     "map sweep: " + std::to_string(pending.size()) + " points to run" +
                         (ranks > 1 ? " on " + std::to_string(ranks) + " ranks" : ""));

  auto run_point = [&](int index) {
    SweepPoint p;
    p.index = index;
    p.ratios = grid[index];
    const auto point_start = std::chrono::steady_clock::now();
    const MaterialParameters material =
        MaterialAt(p.ratios, options.normal_stiffness_n_per_m, options.bond_tensile_strength_n,
                   options.density_kg_per_m3, options.plane_model, group_length);
    try {
      LabTestOptions test = StrengthTestProtocol(options.test);
      test.progress = nullptr;
      test.record_snapshots = false;
      test.kind = LabTestKind::kUniaxialCompression;
      const LabTestResult ucs = RunLabTest<Dim>(ucs_packing, material, test);
      test.kind = LabTestKind::kBrazilian;
      const LabTestResult bts = RunLabTest<Dim>(bts_packing, material, test);
      p.ucs_peak_reached = ucs.peak_reached;
      p.bts_peak_reached = bts.peak_reached;
      if (!ucs.peak_reached || !bts.peak_reached)
        throw ComputationError(std::string("the ") + (!ucs.peak_reached ? "UCS" : "Brazilian") +
                               " test reached its strain limit without a peak");
      // E and nu of the intact specimen (intact_elastic.h), what the calibration matches.
      const ElasticMeasurement elastic = MeasureIntactElasticConstants<Dim>(ucs_packing, material, options.test);
      p.youngs_modulus_pa = elastic.youngs_modulus_pa;
      p.poisson_ratio = elastic.poisson_ratio;
      p.ucs_pa = ucs.peak_stress_pa;
      p.tensile_strength_pa = bts.tensile_strength_pa;
      p.elastic_group = ElasticGroup(sweep.ucs_descriptors, p.youngs_modulus_pa, material.normal_stiffness_n_per_m);
      p.compressive_group = StrengthGroup(sweep.ucs_descriptors, p.ucs_pa, material.bond_tensile_strength_n);
      p.tensile_group = StrengthGroup(sweep.bts_descriptors, p.tensile_strength_pa, material.bond_tensile_strength_n);
      p.ok = true;
    } catch (const ComputationError& e) {
      p.ok = false;
      p.failure = e.what();
    }
    p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - point_start).count();
    std::lock_guard<std::mutex> lock(mutex);
    sweep.points[index] = p;
    if (journaled) {
      nlohmann::json line = {{"design", key}, {"point", p.ToJson()}};
      AppendJournalLine(journal, line.dump());
      if (++journaled_here == exit_after) std::_Exit(9);
    }
    finished_queue.push_back(index * 2 + (p.ok ? 1 : 0));
    finished_signal.notify_one();
  };

  // The rank's first error that stops the sweep names the point (and the rank, with several).
  auto describe_point = [&](int index) {
    const MicroRatios& r = grid[index];
    std::string text = "point " + std::to_string(index + 1) + " of " + std::to_string(total) + " (kt/kn " +
                       Number(r.tangential_to_normal_stiffness) + ", Rt/Rn " + Number(r.shear_to_tensile_strength);
    if (r.normal_stiffness_to_particle > 0) text += ", kn/(Ep l) " + Number(r.normal_stiffness_to_particle);
    text += ")";
    if (ranks > 1) text += " on rank " + std::to_string(rank);
    return text;
  };
  auto worker = [&]() {
    for (;;) {
      const int k = next++;
      if (k >= static_cast<int>(mine.size())) break;
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (!stop.message.empty()) break;
      }
      try {
        run_point(mine[k]);
      } catch (const std::exception& e) {  // input or file errors stop the sweep
        std::lock_guard<std::mutex> lock(mutex);
        if (stop.message.empty())
          stop = {describe_point(mine[k]) + ": " + e.what(), dynamic_cast<const FileError*>(&e) != nullptr};
        break;
      }
    }
    std::lock_guard<std::mutex> lock(mutex);
    --running_workers;
    finished_signal.notify_one();
  };

  // Workers run the points; this (the MPI) thread reports: rank 0 counts its own points and
  // the notes of the other ranks (points done out of the total across ranks), the others
  // send a note per finished point and one (-1) when their share is done.
  auto report = [&](int count, int index, bool ok, int on_rank) {
    if (!options.progress) return;
    const MicroRatios& r = grid[index];
    char message[200];
    std::snprintf(message, sizeof(message), "map sweep: point %d of %d (kt/kn %.3g, Rt/Rn %.3g%s) %s%s", count, total,
                  r.tangential_to_normal_stiffness, r.shear_to_tensile_strength,
                  r.normal_stiffness_to_particle > 0 ? (", kn/(Ep l) " + Number(r.normal_stiffness_to_particle)).c_str()
                                                     : "",
                  ok ? "done" : "failed", ranks > 1 ? (" (rank " + std::to_string(on_rank) + ")").c_str() : "");
    options.progress(static_cast<double>(count) / total, message);
  };
  const int workers = stop.message.empty() ? std::min<int>(options.workers, static_cast<int>(mine.size())) : 0;
  running_workers = workers;
  std::vector<std::thread> threads;
  for (int w = 0; w < workers; ++w) threads.emplace_back(worker);
  int count = sweep.resumed_points;
  int ranks_done = 1;  // rank 0: the ranks whose share is done (itself once its workers are)
  bool own_done = false;
  for (;;) {
    std::vector<int> events;
    bool workers_done = false;
    {
      std::unique_lock<std::mutex> lock(mutex);
      auto ready = [&] { return !finished_queue.empty() || running_workers == 0; };
      if (ranks == 1) finished_signal.wait(lock, ready);
      else finished_signal.wait_for(lock, std::chrono::milliseconds(20), ready);
      events.swap(finished_queue);
      workers_done = running_workers == 0;
    }
    for (int e : events) {
      if (rank == 0) report(++count, e / 2, e % 2 == 1, 0);
      else SendNoteToRoot(e);
    }
    if (workers_done && !own_done) {
      own_done = true;
      if (rank > 0) SendNoteToRoot(-1);
    }
    for (const RankNote& note : ReceiveNotes()) {
      if (note.value < 0) ++ranks_done;
      else report(++count, note.value / 2, note.value % 2 == 1, note.rank);
    }
    if (own_done && (rank > 0 || ranks_done == ranks)) break;
  }
  for (auto& t : threads) t.join();
  CompleteNotes();

  // Every rank's points (and its stop, if any) to every rank: the same sweep, the same fit.
  if (ranks > 1) {
    nlohmann::json share = {{"points", nlohmann::json::array()}, {"stop", stop.message}, {"file", stop.file}};
    for (int index : mine)
      if (sweep.points[index].index == index) share["points"].push_back(sweep.points[index].ToJson());
    stop = SweepStop();
    for (const std::string& text : AllGather(share.dump())) {
      const nlohmann::json other = nlohmann::json::parse(text);
      for (const nlohmann::json& j : other.at("points")) {
        const SweepPoint p = SweepPoint::FromJson(j);
        sweep.points.at(p.index) = p;
      }
      if (stop.message.empty()) stop = {other.at("stop").get<std::string>(), other.at("file").get<bool>()};
    }
  }
  if (!stop.message.empty() && stop.file) throw FileError("map sweep stopped: " + stop.message);
  if (!stop.message.empty())
    throw ComputationError("map sweep stopped on its specimens (UCS " + std::to_string(ucs_packing.size()) +
                     " particles, Brazilian " + std::to_string(bts_packing.size()) + "): " + stop.message +
                     " (larger map specimens: more particles or a larger sweep share)");

  for (const SweepPoint& p : sweep.points) sweep.failed_points += p.ok ? 0 : 1;
  sweep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return sweep;
}

void RemoveSweepJournals(const std::string& journal_path) {
  if (journal_path.empty()) return;
  // Test hook (tests/tools/mpi_sweep_test.py): keep them to count the points each run finished.
  if (std::getenv("SPECIMEN_TEST_KEEP_JOURNALS")) return;
  for (const std::string& file : JournalFiles(journal_path)) std::filesystem::remove(file);
}

MapSet FitMaps(const MapSweep& sweep, const SweepDesign& design, int max_total_degree) {
  const std::vector<MicroRatio> inputs = design.Inputs();
  MapSet maps;
  maps.inputs = inputs;
  maps.fixed = design.fixed;
  std::vector<const SweepPoint*> ok;
  for (const SweepPoint& p : sweep.points)
    if (p.ok) ok.push_back(&p);
  Eigen::MatrixXd x(ok.size(), inputs.size());
  Eigen::VectorXd nu(ok.size()), psi_e(ok.size()), psi_c(ok.size()), psi_t(ok.size());
  for (size_t i = 0; i < ok.size(); ++i) {
    const std::vector<double> row = maps.InputsOf(ok[i]->ratios);
    for (size_t k = 0; k < row.size(); ++k) x(i, k) = row[k];
    nu[i] = ok[i]->poisson_ratio;
    psi_e[i] = ok[i]->elastic_group;
    psi_c[i] = ok[i]->compressive_group;
    psi_t[i] = ok[i]->tensile_group;
  }
  // E and nu are elastic: Rt/Rn and mu act only once bonds break, so the elastic surfaces
  // do not vary with them (a constant column carries no powers, response_surface.h). Fewer
  // terms, and no spurious cross terms where failed sweep points leave holes.
  Eigen::MatrixXd x_elastic = x;
  for (size_t k = 0; k < inputs.size(); ++k)
    if (inputs[k] == MicroRatio::kStrengthRatio || inputs[k] == MicroRatio::kFriction)
      x_elastic.col(k).setConstant(x.rows() > 0 ? x(0, k) : 0.0);
  ResponseSurfaceOptions fit;
  fit.max_total_degree = max_total_degree;
  try {
    maps.poisson_ratio = ResponseSurface::Fit(x_elastic, nu, fit);
    maps.elastic_group = ResponseSurface::Fit(x_elastic, psi_e, fit);
    ResponseSurfaceOptions strength_fit = fit;
    strength_fit.log_values = true;  // the strength groups: in logarithms (response_surface.h)
    maps.compressive_group = ResponseSurface::Fit(x, psi_c, strength_fit);
    maps.tensile_group = ResponseSurface::Fit(x, psi_t, strength_fit);
  } catch (const InputError& e) {
    throw InputError("cannot fit the maps: " + std::to_string(ok.size()) + " of " +
                     std::to_string(sweep.points.size()) + " sweep points succeeded (" + e.what() +
                     "); lower the surface degree or widen the sweep");
  }
  return maps;
}

template MapSweep RunMapSweep<2>(const Packing<2>&, const Packing<2>&, const SweepDesign&, const MapSweepOptions&);
template MapSweep RunMapSweep<3>(const Packing<3>&, const Packing<3>&, const SweepDesign&, const MapSweepOptions&);
template MapSweep RunSweepPoints<2>(const Packing<2>&, const Packing<2>&, const std::vector<MicroRatios>&,
                                    const MapSweepOptions&);
template MapSweep RunSweepPoints<3>(const Packing<3>&, const Packing<3>&, const std::vector<MicroRatios>&,
                                    const MapSweepOptions&);

}  // namespace specimen
