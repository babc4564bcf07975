// A shared library opened at run time (dlopen; LoadLibrary on Windows), for what must never be
// linked at build time: the vendors' haptic libraries (OpenHaptics, Force Dimension) and libusb for
// the Falcon. The first of several names that loads wins; a missing library or symbol is an error
// that names it.
#pragma once
#include <memory>
#include <string>
#include <vector>

namespace hs {

/// Built for Windows: a vendor's library has its Windows file name there (hd.dll, not libHD.so).
#ifdef _WIN32
inline constexpr bool kWindows = true;
#else
inline constexpr bool kWindows = false;
#endif

class SharedLibrary {
public:
    /// Opens the first of `names` that loads (a name with a '/' (or '\\' on Windows) is a path, else
    /// the loader's search path). std::runtime_error listing what was tried and why each failed.
    static SharedLibrary open(const std::vector<std::string>& names, const std::string& what);
    /// The library that loaded (its name as given).
    const std::string& name() const { return name_; }
    /// The symbol's address; std::runtime_error naming it and the library when it is missing.
    void* symbol(const char* symbolName) const;
    /// The symbol as a function pointer of type F.
    template <class F>
    F function(const char* symbolName) const {
        return reinterpret_cast<F>(symbol(symbolName));
    }

private:
    struct Closer {
        void operator()(void* handle) const;
    };
    SharedLibrary(std::shared_ptr<void> handle, std::string name) : handle_(std::move(handle)), name_(std::move(name)) {}
    std::shared_ptr<void> handle_;
    std::string name_;
};

}  // namespace hs
