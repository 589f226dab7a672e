// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What an `ictk` subcommand is: an object that adds itself to the application (its options bound
// to its own members) and runs once they are parsed. main.cxx lists the commands (one factory
// each, below, defined in <Name>Command.cxx); every command reports a user error by throwing, and
// main turns the exception into one line "ictk: error: ..." and exit code 2.

#include <memory>
#include <stdexcept>

namespace CLI
{
class App;
}

namespace ictk::cli
{

/// Exit codes: 0 success; 1 a check that found a problem (`validate`); 2 a user error (bad input,
/// unwritable output, a model with errors); 130 interrupted by Ctrl-C (nothing written).
constexpr int ExitUserError = 2;
constexpr int ExitInterrupted = 130;

/// A user error: reported as one line "ictk: error: <what>", exit code 2.
class UserError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// A model file's diagnostics: already "file:line:col: error: ..." lines, printed as they are.
class ModelFileError : public UserError
{
public:
  using UserError::UserError;
};

class Command
{
public:
  virtual ~Command() = default;
  /// Adds the subcommand and its options to `app`; returns it (main runs the one that was given).
  virtual CLI::App* add(CLI::App& app) = 0;
  /// Runs the parsed command; returns the exit code. Throws std::exception (UserError, or
  /// lang::ParseError for a model's diagnostics) on a user error.
  virtual int run() = 0;
};

std::unique_ptr<Command> modelsCommand();   // ModelsCommand.cxx
std::unique_ptr<Command> evalCommand();     // EvalCommand.cxx
std::unique_ptr<Command> sampleCommand();   // SampleCommand.cxx
std::unique_ptr<Command> convertCommand();  // ConvertCommand.cxx
std::unique_ptr<Command> benchCommand();    // BenchCommand.cxx
std::unique_ptr<Command> meshCommand();     // MeshCommand.cxx
std::unique_ptr<Command> renderCommand();   // RenderCommand.cxx
std::unique_ptr<Command> tetraCommand();    // TetraCommand.cxx
std::unique_ptr<Command> studyCommand();    // StudyCommand.cxx
std::unique_ptr<Command> solveCommand();    // SolveCommand.cxx
std::unique_ptr<Command> runCommand();      // RunCommand.cxx
std::unique_ptr<Command> infoCommand();     // InfoCommand.cxx
std::unique_ptr<Command> validateCommand(); // ValidateCommand.cxx

} // namespace ictk::cli
