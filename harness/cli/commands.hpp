#pragma once
// The `sandbench` subcommands. Each registers itself on the CLI11 app; its callback does the
// work and throws InputError for bad input (exit code 2).
#include <CLI/CLI.hpp>

namespace sb::cli {

void add_run_command(CLI::App& app);
void add_compare_command(CLI::App& app);
void add_interactive_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_export_command(CLI::App& app);

}  // namespace sb::cli
