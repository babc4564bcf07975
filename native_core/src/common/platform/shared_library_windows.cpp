#include "common/platform/shared_library.hpp"

#include <windows.h>

#include <stdexcept>

namespace hs {

namespace {
/// The system's message for error `code`, on one line.
std::string systemMessage(DWORD code) {
    char* text = nullptr;
    const DWORD n = FormatMessageA(FORMAT_MESSAGE_ALLOCATE_BUFFER | FORMAT_MESSAGE_FROM_SYSTEM | FORMAT_MESSAGE_IGNORE_INSERTS,
                                   nullptr, code, 0, reinterpret_cast<char*>(&text), 0, nullptr);
    std::string out = n && text ? std::string(text, n) : "error " + std::to_string(code);
    LocalFree(text);
    while (!out.empty() && (out.back() == '\n' || out.back() == '\r' || out.back() == ' ')) out.pop_back();
    return out;
}
}  // namespace

void SharedLibrary::Closer::operator()(void* handle) const {
    if (handle) FreeLibrary(static_cast<HMODULE>(handle));
}

SharedLibrary SharedLibrary::open(const std::vector<std::string>& names, const std::string& what) {
    std::string tried;
    for (const std::string& n : names) {
        if (HMODULE h = LoadLibraryA(n.c_str()))
            return SharedLibrary(std::shared_ptr<void>(static_cast<void*>(h), Closer{}), n);
        tried += "\n  " + n + ": " + systemMessage(GetLastError());
    }
    throw std::runtime_error(what + ": no library loads; tried:" + tried);
}

void* SharedLibrary::symbol(const char* symbolName) const {
    FARPROC p = GetProcAddress(static_cast<HMODULE>(handle_.get()), symbolName);
    if (!p) throw std::runtime_error(name_ + ": has no symbol " + symbolName + " (not the library expected, or too old)");
    return reinterpret_cast<void*>(p);
}

}  // namespace hs
