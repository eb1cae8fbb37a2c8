// The end of every app's main(): parse the command line, run, and turn what was thrown into a
// message naming the app and an exit code (1: a step failed, 2: anything else; CLI11's own for a
// bad command line). Bad input never crashes an app (tests/apps).
#pragma once

#include "core/integrate/integrator.hpp"

#include <CLI/CLI.hpp>

#include <exception>
#include <iostream>
#include <string_view>

namespace tissue::apps {

template <class Run>
int parse_and_run(CLI::App& app, int argc, char** argv, std::string_view name, Run&& run) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error);
  }
  try {
    return run();
  } catch (const IntegrationError& error) {
    std::cerr << name << ": step failed: " << error.what() << '\n';
    return 1;
  } catch (const std::exception& error) {
    std::cerr << name << ": " << error.what() << '\n';
    return 2;
  }
}

}  // namespace tissue::apps
