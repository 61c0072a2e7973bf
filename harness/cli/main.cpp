// sandbench: the command line. Exit codes: 0 success, 2 bad input, 1 internal error.
#include <CLI/CLI.hpp>
#include <iostream>

#include "common/input_error.hpp"
#include "harness/cli/commands.hpp"
#include "sandbench/version.hpp"

int main(int argc, char** argv) {
  CLI::App app{"sandbench: TIN vs grid terrains for interactive sand manipulation"};
  app.set_version_flag("--version", std::string("sandbench ") + sb::kVersion + " commit " + sb::kCommit + " build " +
                                        sb::kBuildId + " (" + sb::kCompiler + ", " + sb::kBuildType + ")");
  app.require_subcommand(1);
  sb::cli::add_run_command(app);
  sb::cli::add_compare_command(app);
  sb::cli::add_interactive_command(app);
  sb::cli::add_render_command(app);
  sb::cli::add_export_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  } catch (const sb::InputError& e) {
    std::cerr << "sandbench: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "sandbench: internal error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
