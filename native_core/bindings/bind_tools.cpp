// The tools: each setting is a property defined from the core's parameter tables (tools.hpp),
// whose set() does the range check.
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "names.hpp"
#include "tools.hpp"

namespace py = pybind11;

namespace hs {
namespace {

template <class Class, class T, class Owner, std::size_t N>
void parameters(Class& cls, const std::array<ToolParameter<T, Owner>, N>& table) {
    for (const auto& p : table)
        cls.def_property(p.name, [p](const T& t) { return p.get(t); }, [p](T& t, double v) { p.set(t, v); }, p.doc);
}

template <class Class, class T>
void falloff(Class& cls) {
    cls.def_property("falloff", [](const T& t) { return std::string(nameOf(kFalloffNames, t.falloff)); },
                     [](T& t, const std::string& s) { t.falloff = fromName(kFalloffNames, s, "falloff"); });
}

}  // namespace

void bindTools(py::module_& m) {
    py::class_<Tool> tool(m, "Tool", "A sculpting tool; the reaction on the cursor is minus the sum of its forces on the surface.");
    tool.def_property_readonly("name", &Tool::name)
        .def_property_readonly("grabbed", &Tool::grabbed)
        .def_property_readonly("anchor", &Tool::anchor, "Mesh index the tool holds, -1 if none");
    parameters(tool, kToolLimitParameters);

    m.attr("ROPE_PLATE_GAIN") = kRopePlateGain;
    py::class_<RopeTool, Tool> rope(m, "RopeTool");
    parameters(rope, kRopeParameters);
    rope.def_property_readonly("rest_length", &RopeTool::restLength)
        .def_property_readonly("gain", &RopeTool::gain,
                               "its pull over its settings where it is tied: 1 + ROPE_PLATE_GAIN x the bending ratio there");

    py::class_<MagnetTool, Tool> magnet(m, "MagnetTool");
    parameters(magnet, kMagnetParameters);
    falloff<decltype(magnet), MagnetTool>(magnet);
    magnet.def_property_readonly("selected", &MagnetTool::selected);

    py::class_<OrientationTool, Tool> orientation(m, "OrientationTool");
    parameters(orientation, kOrientationParameters);

    py::class_<SmoothTool, Tool> smooth(m, "SmoothTool");
    parameters(smooth, kSmoothParameters);
    falloff<decltype(smooth), SmoothTool>(smooth);
}

}  // namespace hs
