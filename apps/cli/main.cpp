// voxfield — command-line front end.
#include <cmath>
#include <iostream>

#include "cli.h"
#include "voxfield/error.h"
#include "voxfield/file.h"
#include "voxfield/limits.h"
#include "voxfield/render.h"

namespace voxfield::cli {
namespace {
std::string g_activity;
}  // namespace

void set_activity(std::string what) {
  g_activity = std::move(what);
}
const std::string& activity() {
  return g_activity;
}

CLI::Validator finite_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double v = 0;
        try {
          std::size_t used = 0;
          v = std::stod(text, &used);
          if (used != text.size()) return "\"" + text + "\" is not a number";
        } catch (const std::exception&) {
          return "\"" + text + "\" is not a number";
        }
        if (!std::isfinite(v)) return "must be a finite number, got " + text;
        return {};
      },
      "NUMBER");
}

CLI::Validator finite_non_negative() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::string copy = text;
        const std::string e = finite_number().operator()(copy);
        if (!e.empty()) return e;
        if (std::stod(text) < 0) return "must be a finite number >= 0, got " + text;
        return {};
      },
      "NUMBER >= 0");
}

CLI::Validator finite_positive() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::string copy = text;
        const std::string e = finite_non_negative().operator()(copy);
        if (!e.empty()) return e;
        if (std::stod(text) == 0) return "must be a finite number > 0, got " + text;
        return {};
      },
      "NUMBER > 0");
}

CLI::Validator camera_spec() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        try {
          (void)Camera::parse(text, Box3i::from_size({1, 1, 1}), 1.0);
        } catch (const Error& e) {
          return e.what();
        }
        return {};
      },
      "CAMERA");
}

}  // namespace voxfield::cli

int main(int argc, char** argv) {
  // Ctrl-C, SIGTERM, SIGHUP: remove the temporaries of outputs being written, then stop.
  voxfield::install_signal_cleanup();
  CLI::App app{"voxfield: distance fields and more from editable voxel worlds"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "voxfield 0.1.0");
  std::string memory_limit;
  app.add_option("--memory-limit", memory_limit,
                 "refuse inputs and buffers needing more memory than this (e.g. 8G; default: "
                 "$VOXFIELD_MEMORY_LIMIT, else half of physical memory)");
  voxfield::cli::Action action;
  voxfield::cli::add_info(app, action);
  voxfield::cli::add_convert(app, action);
  voxfield::cli::add_field(app, action);
  voxfield::cli::add_compare(app, action);
  voxfield::cli::add_edit(app, action);
  voxfield::cli::add_bench(app, action);
  voxfield::cli::add_render(app, action);
  voxfield::cli::add_mesh(app, action);
  voxfield::cli::add_csg(app, action);
  voxfield::cli::add_vectors(app, action);
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
    // The first word that is neither an option nor a command is named as an unknown command.
    std::string names;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands({})) {
      names += (names.empty() ? "" : ", ") + sub->get_name();
      known = known || (argc > 1 && sub->get_name() == argv[1]);
    }
    if (argc > 1 && argv[1][0] != '-' && !known) {
      std::cerr << "voxfield: unknown command \"" << argv[1] << "\" (commands: " << names
                << "; see --help)\n";
      return 2;
    }
    app.exit(e);  // prints the message and usage
    return 2;
  }
  try {
    if (!memory_limit.empty()) {
      try {
        voxfield::set_default_memory_limit(
            voxfield::parse_byte_size(memory_limit, "--memory-limit"));
      } catch (const voxfield::InvalidArgument& e) {
        std::cerr << "voxfield: " << e.what() << "\n";
        return 2;
      }
    }
    try {
      (void)voxfield::default_memory_limit();  // a malformed VOXFIELD_MEMORY_LIMIT is reported here
    } catch (const voxfield::InvalidArgument& e) {
      std::cerr << "voxfield: " << e.what() << "\n";
      return 2;
    }
    return action ? action() : 2;
  } catch (const voxfield::cli::UsageError& e) {
    std::cerr << "voxfield: " << e.what() << "\n";
    return 2;
  } catch (const voxfield::Error& e) {
    std::cerr << "voxfield: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    const std::string& doing = voxfield::cli::activity();
    std::cerr << "voxfield: error: out of memory"
              << (doing.empty() ? std::string() : " while " + doing) << " (the memory limit is "
              << voxfield::format_bytes(voxfield::default_memory_limit())
              << "; the machine or the process's own limits ran out first)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "voxfield: error: " << e.what() << "\n";
    return 1;
  }
}
