#include "common/plot.h"

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "common/atomic_file.h"

namespace specimen {

bool GnuplotAvailable() {
  return std::system("command -v gnuplot >/dev/null 2>&1") == 0;
}

std::string GnuplotQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) {
    if (c == '\'') quoted += "''";
    else quoted += c;
  }
  return quoted + "'";
}

bool RenderGnuplot(const std::string& script, const std::string& output_png,
                   const PlotOptions& options, std::string* error) {
  if (!GnuplotAvailable()) {
    if (error) *error = "gnuplot not found (apt-get install gnuplot-nox); picture skipped";
    return false;
  }
  const std::string temporary_png = output_png + ".tmp.png";
  const std::string script_path = output_png + ".tmp.gp";
  {
    std::ofstream out(script_path);
    out << "set terminal pngcairo size " << options.width_px << "," << options.height_px
        << " enhanced font 'sans,11'\n"
        << "set output " << GnuplotQuote(temporary_png) << "\n"
        << script << "\nunset output\n";
    if (!out) {
      if (error) *error = "cannot write the plot script next to '" + output_png + "'";
      return false;
    }
  }
  std::string shell_quoted = "'";
  for (char c : script_path) shell_quoted += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  shell_quoted += "'";
  const std::string command = "gnuplot " + shell_quoted + " >/dev/null 2>&1";
  const int status = std::system(command.c_str());
  std::remove(script_path.c_str());
  if (status != 0 || std::rename(temporary_png.c_str(), output_png.c_str()) != 0) {
    std::remove(temporary_png.c_str());
    if (error) *error = "gnuplot failed to draw '" + output_png + "'";
    return false;
  }
  return true;
}

}  // namespace specimen
