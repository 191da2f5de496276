// The subcommands of `tetstream`. Each registers its options on the CLI11 app and returns a
// runner that yields the process exit code.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>

namespace tetstream::cli {

using Runner = std::function<int()>;

Runner addGen(CLI::App& app);
Runner addPack(CLI::App& app);
Runner addIso(CLI::App& app);
Runner addInfo(CLI::App& app);
Runner addUnpack(CLI::App& app);

}  // namespace tetstream::cli
