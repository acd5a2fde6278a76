#include "maps/module_loader.hpp"

#include <dlfcn.h>
#include <limits.h>
#include <unistd.h>

#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <vector>

#ifndef SKYLANE_INSTALL_LIBDIR
#define SKYLANE_INSTALL_LIBDIR "lib"  // CMake defines it: CMAKE_INSTALL_LIBDIR
#endif

namespace skylane::maps::detail {
namespace {

/// The directory of the running executable ("" when /proc/self/exe cannot be read).
std::string executableDir() {
  char buf[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return {};
  const std::string exe(buf, static_cast<std::size_t>(n));
  const std::size_t slash = exe.rfind('/');
  return slash == std::string::npos ? std::string() : exe.substr(0, slash);
}

/// Where the module may be, in the order they are tried.
std::vector<std::string> candidatePaths(const ModuleSpec& spec) {
  std::vector<std::string> paths;
  const char* env = std::getenv(spec.env_var);
  if (env != nullptr && *env != '\0') paths.emplace_back(env);
  const std::string dir = executableDir();
  if (!dir.empty()) {
    paths.push_back(dir + "/" + spec.file);
    paths.push_back(dir + "/../" + spec.file);  // tests/ and bench/ sit below the build dir
    paths.push_back(dir + "/../" SKYLANE_INSTALL_LIBDIR "/skylane/" + spec.file);  // PREFIX/bin → PREFIX/lib/skylane
  }
  if (*spec.build_path != '\0') paths.emplace_back(spec.build_path);
  if (*spec.install_path != '\0') paths.emplace_back(spec.install_path);
  return paths;
}

}  // namespace

void* loadModuleEntry(const ModuleSpec& spec) {
  std::ostringstream tried;
  for (const std::string& path : candidatePaths(spec)) {
    if (::access(path.c_str(), F_OK) != 0) {
      tried << "; " << path << ": absent";
      continue;
    }
    // RTLD_NODELETE: objects made by the module (transformations held by a terrain) may outlive
    // any handle; RTLD_LOCAL: its libraries' symbols stay out of the global scope.
    void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (handle == nullptr) {
      const char* why = ::dlerror();
      tried << "; " << path << ": " << (why != nullptr ? why : "dlopen failed");
      continue;
    }
    void* entry = ::dlsym(handle, spec.entry_point);
    if (entry == nullptr) {
      tried << "; " << path << ": no " << spec.entry_point << " (a module from another skylane version)";
      continue;
    }
    return entry;
  }
  throw std::runtime_error(std::string(spec.needed_for) + " needs skylane's module " + spec.file +
                           " (install it beside skylane or set " + spec.env_var + "); looked at: " +
                           tried.str().substr(2));
}

}  // namespace skylane::maps::detail
