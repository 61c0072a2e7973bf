// sandbench: the command line. Exit codes: 0 success, 2 bad input (the message names it),
// 1 internal error (a bug).
#include <CLI/CLI.hpp>
#include <iostream>

#include "common/input_error.hpp"
#include "harness/cli/commands.hpp"
#include "harness/run/preflight.hpp"
#include "sandbench/version.hpp"

namespace {

std::vector<CLI::App*> commands(CLI::App& app) {
  return app.get_subcommands([](CLI::App*) { return true; });
}

std::string command_list(CLI::App& app) {
  std::string list;
  for (CLI::App* c : commands(app)) list += (list.empty() ? "" : ", ") + c->get_name();
  return list;
}

CLI::App* find_command(CLI::App& app, const std::string& name) {
  for (CLI::App* c : commands(app))
    if (c->get_name() == name) return c;
  return nullptr;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sandbench: TIN vs grid terrains for interactive sand manipulation"};
  app.set_version_flag("-V,--version", std::string("sandbench ") + sb::kVersion + " commit " + sb::kCommit + " build " +
                                           sb::kBuildId + " (" + sb::kCompiler + ", " + sb::kBuildType + ")");
  app.require_subcommand(1);
  sb::cli::add_run_command(app);
  sb::cli::add_compare_command(app);
  sb::cli::add_interactive_command(app);
  sb::cli::add_render_command(app);
  sb::cli::add_export_command(app);
  sb::cli::add_scene_keys_command(app);

  // The first word names the command: `help [COMMAND]` prints help; anything unknown is an
  // error that lists the commands (CLI11 alone would say "A subcommand is required").
  if (argc < 2) {
    std::cerr << "sandbench: error: a command is required: " << command_list(app)
              << "\n(sandbench --help, or sandbench COMMAND --help)\n";
    return 2;
  }
  const std::string first = argv[1];
  if (first == "help") {
    CLI::App* about = argc > 2 ? find_command(app, argv[2]) : nullptr;
    if (argc > 2 && !about) {
      std::cerr << "sandbench: error: help: unknown command '" << argv[2] << "'; commands: " << command_list(app)
                << "\n";
      return 2;
    }
    std::cout << (about ? about->help() : app.help());
    return 0;
  }
  if (first.empty() || (first[0] != '-' && !find_command(app, first))) {
    std::cerr << "sandbench: error: unknown command '" << first << "'; commands: " << command_list(app)
              << "\n(sandbench --help, or sandbench COMMAND --help)\n";
    return 2;
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // Name the command whose options were wrong, and where its options are listed.
    std::string where = "sandbench";
    for (CLI::App* c : app.get_subcommands()) where += " " + c->get_name();
    std::cerr << where << ": error: " << e.what() << "\n(" << where << " --help lists the options)\n";
    return 2;
  } catch (const sb::InputError& e) {
    std::cerr << "sandbench: error: " << e.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    // Name the input behind the largest allocation the pre-flight or a reader foresaw.
    const std::string cause = sb::out_of_memory_context();
    std::cerr << "sandbench: error: out of memory" << (cause.empty() ? "" : " (the largest part: " + cause + ")")
              << "; use a smaller scene (fewer stamps, a coarser grid or raster) or a smaller input\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "sandbench: internal error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
