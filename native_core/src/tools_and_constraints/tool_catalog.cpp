// The catalogue of tools: one per file in tools/. CMake lists those files in tool_list.inc (one
// HS_TOOL(name) line each), so adding a tool is adding its file; nothing here changes.
#include <algorithm>
#include <stdexcept>

#include "common/names.hpp"
#include "tools_and_constraints/tool.hpp"

namespace hs {
namespace tools {
#define HS_TOOL(name) namespace name { std::unique_ptr<Tool> make(); }
#include "tool_list.inc"
#undef HS_TOOL
}  // namespace tools

namespace {
using Maker = std::unique_ptr<Tool> (*)();
struct Entry {
    const char* name;
    Maker make;
};
constexpr Entry kTools[] = {
#define HS_TOOL(name) {#name, &tools::name::make},
#include "tool_list.inc"
#undef HS_TOOL
};
}  // namespace

std::unique_ptr<Tool> makeTool(const std::string& name) {
    for (const Entry& e : kTools)
        if (name == e.name) return e.make();
    std::string known;
    for (const std::string& n : toolNames()) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("tool: unknown tool '" + name + "' (" + known + ")");
}

std::vector<std::string> toolNames() {
    std::vector<std::pair<int, std::string>> ordered;
    for (const Entry& e : kTools) ordered.emplace_back(e.make()->info().order, e.name);
    std::sort(ordered.begin(), ordered.end());
    std::vector<std::string> out;
    for (auto& [order, name] : ordered) out.push_back(std::move(name));
    return out;
}

}  // namespace hs
