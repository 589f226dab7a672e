// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// How `ictk render` writes what the core draws (Render/Canvas.h): a picture as PNG and its depth
// buffer as .vti through VTK's writers, and the pictures of a range of frames as numbered PNGs
// (a printf pattern, frames/%04d.png) or as an .mp4 film encoded by ffmpeg. Everything goes
// through temporary files beside the destination that are moved into place only once every
// frame is written (Output.h), so an error or Ctrl-C leaves no partial picture, sequence or film.

#include "Output.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace ictk::cli
{

/// RGBA pixels, row 0 at the bottom, and their depths (the core's buffers).
struct PictureBuffers
{
  int Width = 0;
  int Height = 0;
  const std::vector<std::uint8_t>* Colour = nullptr;
  const std::vector<double>* Depth = nullptr;
  /// Unit normals facing the camera, 3 a pixel; null or empty when the renderer gives none.
  const std::vector<float>* Normal = nullptr;
};

/// Writes the colour as PNG into `file` (an AtomicOutput of `path`) and commits it.
void WritePng(const PictureBuffers& picture, AtomicOutput& file, const std::string& path);
/// Writes the depth buffer (array `depth`, inf where nothing is hit) and, when there is one, the
/// normal buffer (array `normal`, 3 components, 0 where nothing is hit) as .vti into `file`
/// (through WriteXml: a full disk fails cleanly) and commits it.
void WriteDepth(const PictureBuffers& picture, AtomicOutput& file);

/// The destination of a range of frames: a pattern with one printf integer conversion (%d,
/// %04d; %% for a percent sign) ending in .png, or an .mp4 file (needs ffmpeg on the PATH: the
/// Debian package `ffmpeg`). The constructor checks it (UserError, before any work): a pattern's
/// folder is made when it does not exist (its parent must).
class FrameOutput
{
public:
  /// `framesPerSecond` is the film's (ignored for PNGs).
  FrameOutput(const std::string& output, double framesPerSecond);
  ~FrameOutput();
  FrameOutput(const FrameOutput&) = delete;
  FrameOutput& operator=(const FrameOutput&) = delete;

  /// True for an .mp4 destination.
  static bool IsFilm(const std::string& output);
  /// The file name of frame k of a pattern.
  std::string FrameName(std::size_t k) const;
  /// Writes frame k (numbered from 0) to its temporary place.
  void Write(std::size_t k, const PictureBuffers& picture);
  /// Moves every frame into place, or encodes the film and moves it; returns what was written
  /// (the film, or the first and last frame's names).
  std::string Commit();

private:
  std::string Output;
  bool Film = false;
  double FramesPerSecond = 0;
  std::string MadeFolder;    ///< the pattern's folder, when this made it
  std::string StagingFolder; ///< the film's frames
  std::vector<std::unique_ptr<AtomicOutput>> Frames;
  std::vector<std::string> Names;
  bool Committed = false;
};

} // namespace ictk::cli
