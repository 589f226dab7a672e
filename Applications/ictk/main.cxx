// SPDX-License-Identifier: BSD-3-Clause
// ictk: the command-line face of ICTK. One file per command (<Name>Command.cxx, each a Command,
// Command.h); the helpers they share by concern: Options (shared options, number lists, frame
// ranges), Models (what a `model` argument names), Output (atomic outputs), Progress (progress
// bar, Ctrl-C, timing), VtkMessages (VTK's errors as one line) and GridSampling (sample, mesh).
//
//   ictk models | eval | sample | mesh | convert      models and model files
//   ictk info | validate | mesh | tetra | study        complexes
//   ictk render MODEL -o picture.png                   a picture, ray-cast
//   ictk run MODEL.icm --frames T0:T1:DT -o out.pvd    a dynamic complex, one .vtpc per frame
//   ictk bench                                         the performance workloads
//
// Every user error ends in one line "ictk: error: ..." on stderr and exit code 2 (a model file's
// diagnostics are printed as they are); nothing is left half-written (Output.h).

#include "Command.h"
#include "Models.h"
#include "VtkMessages.h"

#include "Lang/Diagnostics.h"

#include <vtkSMPTools.h>

#include <CLI/CLI.hpp>

#include <cstdlib>
#include <iostream>
#include <memory>
#include <new>
#include <string>
#include <vector>

namespace
{

using namespace ictk::cli;

int Run(int argc, char** argv)
{
  CLI::App app{ "ICTK: Implicit Complex ToolKit command-line tool", "ictk" };
  app.set_version_flag("--version", "ictk 0.1.0");
  app.require_subcommand(1);
  // VTK's own error reports are turned into ICTK's one-line errors (VtkMessages.h); --verbose
  // shows them as VTK wrote them. Given before or after the subcommand (fallthrough).
  bool verbose = false;
  app.add_flag("--verbose", verbose, "Also print VTK's own error and warning reports");
  bool strict = false;
  app.add_flag("--strict", strict,
    "Read .hf files as HyperFun's own interpreter does: what ICTK accepts beyond it (its own "
    "library functions, calls of functions defined later) is an error (docs/hyperfun.md)");
  app.fallthrough();

  // In the order `ictk --help` lists them.
  std::vector<std::unique_ptr<Command>> commands;
  commands.push_back(modelsCommand());
  commands.push_back(evalCommand());
  commands.push_back(sampleCommand());
  commands.push_back(convertCommand());
  commands.push_back(benchCommand());
  commands.push_back(meshCommand());
  commands.push_back(renderCommand());
  commands.push_back(tetraCommand());
  commands.push_back(studyCommand());
  commands.push_back(solveCommand());
  commands.push_back(runCommand());
  commands.push_back(infoCommand());
  commands.push_back(validateCommand());
  std::vector<CLI::App*> subcommands;
  for (const auto& command : commands)
  {
    subcommands.push_back(command->add(app));
  }

  try
  {
    app.parse(argc, argv);
  }
  catch (const CLI::CallForHelp& e)
  {
    return app.exit(e);
  }
  catch (const CLI::CallForAllHelp& e)
  {
    return app.exit(e);
  }
  catch (const CLI::CallForVersion& e)
  {
    return app.exit(e);
  }
  catch (const CLI::ParseError& e)
  {
    throw UserError(std::string(e.what()) + " (see ictk --help)");
  }

  CaptureVtkMessages(verbose);
  ReadHyperFunStrictly(strict);
  for (std::size_t i = 0; i < commands.size(); ++i)
  {
    if (*subcommands[i])
    {
      return commands[i]->run();
    }
  }
  return ExitUserError; // unreachable: exactly one subcommand is required
}

} // namespace

int main(int argc, char** argv)
{
  // VTK's filters (Flying Edges, and vtkSampleFunction in `ictk bench`) on as many threads as
  // ICTK's own: ParaView's VTK has no TBB backend and starts Sequential unless
  // VTK_SMP_BACKEND_IN_USE names another.
  if (std::string(vtkSMPTools::GetBackend()) == "Sequential" &&
    !std::getenv("VTK_SMP_BACKEND_IN_USE"))
  {
    vtkSMPTools::SetBackend("STDThread");
  }
  try
  {
    return Run(argc, argv);
  }
  catch (const ModelFileError& e)
  {
    std::cerr << e.what() << "\n";
  }
  catch (const ictk::lang::ParseError& e)
  {
    // Diagnostics carry their own "file:line:col: error:" prefix, source line and caret.
    std::cerr << e.what() << "\n";
  }
  catch (const std::bad_alloc&)
  {
    std::cerr << "ictk: error: out of memory\n";
  }
  catch (const std::exception& e)
  {
    std::cerr << "ictk: error: " << e.what() << "\n";
  }
  catch (...)
  {
    std::cerr << "ictk: error: unexpected failure\n";
  }
  return ExitUserError;
}
