#include "texel/detail/shared_object.hpp"

#include <dlfcn.h>

#include <string>

#include "texel/error.hpp"

namespace texel::detail {

void* open_shared_object(const char* soname, std::string_view needed_for) {
  void* handle = dlopen(soname, RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* why = dlerror();
    throw IoError(std::string(needed_for) + " need the shared library " + soname +
                  ", which cannot be opened: " + (why != nullptr ? why : "unknown reason"));
  }
  return handle;
}

void* shared_object_symbol(void* handle, const char* soname, const char* name) {
  dlerror();  // clear
  void* symbol = dlsym(handle, name);
  if (symbol == nullptr) {
    const char* why = dlerror();
    throw IoError(std::string(soname) + " has no " + name + ": " + (why != nullptr ? why : "null symbol"));
  }
  return symbol;
}

}  // namespace texel::detail
