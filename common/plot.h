#pragma once
// Pictures are drawn by gnuplot (Debian package gnuplot-nox) from the CSV files the
// programs write, so a user can restyle them from the same data. A missing gnuplot is
// not an error: the numbers are still written and the caller reports the skipped picture.

#include <string>

namespace specimen {

struct PlotOptions {
  int width_px = 1000;   // PNG size in pixels.
  int height_px = 800;
};

// True if a gnuplot executable is on PATH.
bool GnuplotAvailable();

// Renders `script` (gnuplot commands after `set terminal`/`set output`) into the PNG file
// `output_png`, atomically. Returns false and fills `error` if gnuplot is missing or fails.
bool RenderGnuplot(const std::string& script, const std::string& output_png,
                   const PlotOptions& options, std::string* error);

// Quotes a path for use inside a gnuplot script string.
std::string GnuplotQuote(const std::string& text);

}  // namespace specimen
