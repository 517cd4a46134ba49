#include "generator/packing_outputs.h"

#include <nlohmann/json.hpp>

#include "common/atomic_file.h"
#include "common/format.h"
#include "common/error.h"
#include "specimen_version.h"
#include "generator/exports.h"
#include "generator/packing_io.h"
#include "generator/packing_plots.h"

namespace specimen {

void CheckPackingOutputLocation(const PackingOutputOptions& options) {
  if (std::string rule; !IsValidOutputName(options.name, &rule))
    throw InputError("output name '" + options.name + "' is not allowed: " + rule);
  if (!(options.liggghts_density_kg_per_m3 > 0.0))
    throw InputError("liggghts_density_kg_per_m3 = " + Number(options.liggghts_density_kg_per_m3) +
                     " is not allowed: it must be > 0 kg/m^3");
  EnsureDirectory(options.directory, "output directory");
}

template <int Dim>
PackingOutputsWritten WritePackingOutputs(const Packing<Dim>& packing,
                                          const PackingMetrics<Dim>& metrics,
                                          const nlohmann::json& report,
                                          const PackingOutputOptions& options) {
  CheckPackingOutputLocation(options);
  const std::string base = options.directory + "/" + options.name;
  nlohmann::json full = report;
  full["version"] = kVersion;
  full["metrics"] = MetricsToJson<Dim>(metrics);

  OutputGroup group;
  group.Add(base + ".packing", [&](std::ostream& out) { WritePacking<Dim>(packing, out); });
  group.Add(base + ".vtu", [&](std::ostream& out) { WriteVtu<Dim>(packing, out); });
  group.Add(base + "_yade.txt", [&](std::ostream& out) { WriteYadeSphereList<Dim>(packing, out); });
  group.Add(base + ".liggghts", [&](std::ostream& out) {
    WriteLiggghtsData<Dim>(packing, out, options.liggghts_density_kg_per_m3);
  });
  group.Add(base + "_report.json", [&](std::ostream& out) { out << full.dump(2) << "\n"; });
  PackingOutputsWritten written;
  written.files = group.Commit();

  // The CSV files behind the pictures are written in any case; --no-pictures only skips
  // drawing them.
  PackingPicturesOptions pictures_options;
  pictures_options.draw = options.pictures;
  const PicturesWritten pictures = WritePackingPictures<Dim>(packing, metrics, base, pictures_options);
  written.files.insert(written.files.end(), pictures.files.begin(), pictures.files.end());
  written.warnings = pictures.warnings;
  return written;
}

template PackingOutputsWritten WritePackingOutputs<2>(const Packing<2>&, const PackingMetrics<2>&,
                                                      const nlohmann::json&,
                                                      const PackingOutputOptions&);
template PackingOutputsWritten WritePackingOutputs<3>(const Packing<3>&, const PackingMetrics<3>&,
                                                      const nlohmann::json&,
                                                      const PackingOutputOptions&);

}  // namespace specimen
