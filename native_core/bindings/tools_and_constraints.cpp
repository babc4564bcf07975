// The tools and the constraints' names. A tool's attributes are its parameters (with the limits
// every tool has), its falloff where it takes one and its readouts, all from its ToolInfo: a new
// tool needs nothing here. TOOL_INFO gives Python the same declarations (defaults included).
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "convert.hpp"
#include "common/names.hpp"
#include "tools_and_constraints/constraints.hpp"
#include "tools_and_constraints/tool.hpp"

namespace py = pybind11;

namespace hs {
namespace {

py::tuple names(const std::vector<std::string>& list) {
    py::tuple out(list.size());
    for (std::size_t i = 0; i < list.size(); ++i) out[i] = list[i];
    return out;
}

py::dict parameterDict(const ParameterInfo& p) {
    py::dict d;
    d["default"] = p.value;
    d["allow_zero"] = p.allowZero;
    d["label"] = *p.label ? p.label : p.name;
    d["doc"] = p.doc;
    d["length"] = p.length;
    return d;
}

/// TOOL_INFO[name]: title, tip, order, falloff (bool), parameters {name: {default, allow_zero, doc, label, length}}, readouts {name: doc}.
py::dict toolInfo() {
    py::dict all;
    for (const std::string& name : toolNames()) {
        const ToolInfo& info = makeTool(name)->info();
        py::dict d, parameters, readouts;
        d["title"] = info.title;
        d["tip"] = info.tip;
        d["order"] = info.order;
        d["falloff"] = info.falloff;
        for (int i = 0; i < info.parameterCount(); ++i) parameters[info.parameters[i].name] = parameterDict(info.parameters[i]);
        for (int i = 0; i < info.readoutCount(); ++i) readouts[info.readouts[i].name] = info.readouts[i].doc;
        d["parameters"] = parameters;
        d["readouts"] = readouts;
        all[py::str(name)] = d;
    }
    return all;
}

bool hasParameter(const Tool& t, const std::string& name) {
    const ToolInfo& info = t.info();
    for (int i = 0; i < info.parameterCount(); ++i)
        if (name == info.parameters[i].name) return true;
    return name == kToolLimitParameters[0].name || name == kToolLimitParameters[1].name;
}

py::object attribute(const Tool& t, const std::string& name) {
    if (hasParameter(t, name)) return py::float_(t.get(name));
    if (name == "falloff" && t.info().falloff) return py::str(nameOf(kFalloffNames, t.falloff()));
    const ToolInfo& info = t.info();
    for (int i = 0; i < info.readoutCount(); ++i)
        if (name == info.readouts[i].name) return py::float_(t.readout(i));
    throw py::attribute_error(std::string("the ") + t.name() + " tool has no attribute '" + name + "'");
}

void setAttribute(Tool& t, const std::string& name, const py::object& value) {
    if (hasParameter(t, name)) return t.set(name, py::cast<double>(value));
    if (name == "falloff") return t.setFalloff(fromName(kFalloffNames, py::cast<std::string>(value), "falloff"));
    throw py::attribute_error(std::string("the ") + t.name() + " tool has no setting '" + name + "'");
}

}  // namespace

void bindToolsAndConstraints(py::module_& m) {
    m.attr("TOOLS") = names(toolNames());
    m.attr("TOOL_INFO") = toolInfo();
    m.attr("ROPE_PLATE_GAIN") = kRopePlateGain;
    m.attr("CONSTRAINTS") = namesOf(kConstraintNames);

    py::class_<Tool>(m, "Tool",
                     "A sculpting tool; the reaction on the cursor is minus the sum of its forces on the surface. Its "
                     "settings are attributes named as in TOOL_INFO[tool.name] (plus max_force and ramp_time).")
        .def_property_readonly("name", &Tool::name)
        .def_property_readonly("grabbed", &Tool::grabbed)
        .def_property_readonly("anchor", &Tool::anchor, "Mesh index the tool holds, -1 if none")
        .def("__getattr__", &attribute)
        .def("__setattr__", &setAttribute)
        .def("__dir__", [](const Tool& t) {
            std::vector<std::string> out{"name", "grabbed", "anchor", kToolLimitParameters[0].name, kToolLimitParameters[1].name};
            const ToolInfo& info = t.info();
            for (int i = 0; i < info.parameterCount(); ++i) out.push_back(info.parameters[i].name);
            for (int i = 0; i < info.readoutCount(); ++i) out.push_back(info.readouts[i].name);
            if (info.falloff) out.push_back("falloff");
            return out;
        });
    m.def("make_tool", &makeTool, py::arg("name"), "A tool of the catalogue by name, on its own (unknown names: ValueError).");
}

}  // namespace hs
