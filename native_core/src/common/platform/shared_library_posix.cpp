#include "common/platform/shared_library.hpp"

#include <dlfcn.h>

#include <stdexcept>

namespace hs {

void SharedLibrary::Closer::operator()(void* handle) const {
    if (handle) dlclose(handle);
}

SharedLibrary SharedLibrary::open(const std::vector<std::string>& names, const std::string& what) {
    std::string tried;
    for (const std::string& n : names) {
        // RTLD_LOCAL: a vendor library's symbols stay out of everything else loaded later
        if (void* h = dlopen(n.c_str(), RTLD_NOW | RTLD_LOCAL)) return SharedLibrary(std::shared_ptr<void>(h, Closer{}), n);
        const char* why = dlerror();
        tried += "\n  " + (why ? std::string(why) : n + ": not loadable");
    }
    throw std::runtime_error(what + ": no library loads; tried:" + tried);
}

void* SharedLibrary::symbol(const char* symbolName) const {
    dlerror();
    void* p = dlsym(handle_.get(), symbolName);
    if (!p) throw std::runtime_error(name_ + ": has no symbol " + symbolName + " (not the library expected, or too old)");
    return p;
}

}  // namespace hs
