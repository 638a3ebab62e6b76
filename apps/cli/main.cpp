// voxfield — command-line front end.
#include <iostream>

#include "cli.h"
#include "voxfield/error.h"

int main(int argc, char** argv) {
  CLI::App app{"voxfield: distance fields and more from editable voxel worlds"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "voxfield 0.1.0");
  voxfield::cli::Action action;
  voxfield::cli::add_info(app, action);
  voxfield::cli::add_convert(app, action);
  voxfield::cli::add_field(app, action);
  voxfield::cli::add_compare(app, action);
  voxfield::cli::add_edit(app, action);
  voxfield::cli::add_bench(app, action);
  voxfield::cli::add_render(app, action);
  voxfield::cli::add_generate(app, action);
  voxfield::cli::add_showcase(app, action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);  // prints help, exit code 0
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);  // prints the message and usage
    return 2;
  }
  try {
    return action ? action() : 2;
  } catch (const voxfield::Error& e) {
    std::cerr << "voxfield: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "voxfield: error: out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "voxfield: error: " << e.what() << "\n";
    return 1;
  }
}
