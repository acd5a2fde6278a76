#pragma once
/// \file
/// \brief Loading one of skylane's optional modules (shared libraries opened with dlopen on
/// first use, so that a process that never needs GDAL or OMPL never loads them).

#include <string>

namespace skylane::maps::detail {

/// \brief Where a module is and what it is for.
struct ModuleSpec {
  const char* file;          ///< File name, e.g. "libskylane_gdal.so".
  const char* env_var;       ///< Environment variable that may name its path (tried first).
  const char* entry_point;   ///< The one exported function, its name carrying the ABI version.
  const char* build_path;    ///< Where the build tree put it ("" when unknown).
  const char* install_path;  ///< Where `cmake --install` puts it ("" when unknown).
  const char* needed_for;    ///< "reading rasters", "planning routes" (for the error message).
};

/// \brief The module's entry point, after dlopen (RTLD_NODELETE: never unloaded). Looked for at
/// $env_var, beside the running executable, one directory up (tests/, bench/), in
/// ../lib/skylane/ from it (an installed PREFIX/bin/skylane), build_path, install_path.
/// \throws std::runtime_error naming every place looked at, and why each failed.
[[nodiscard]] void* loadModuleEntry(const ModuleSpec& spec);

/// \brief The table of functions the module's entry point returns (`const Module* entry()`),
/// loaded as loadModuleEntry() says; it lives as long as the process.
template <class Module>
[[nodiscard]] const Module& moduleTable(const ModuleSpec& spec) {
  using Entry = const Module* (*)();
  return *reinterpret_cast<Entry>(loadModuleEntry(spec))();
}

}  // namespace skylane::maps::detail
