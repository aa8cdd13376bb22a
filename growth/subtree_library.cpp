#include "growth/subtree_library.h"

#include <cmath>
#include <set>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "growth/embedded_data.h"

namespace lobe {

using nlohmann::json;

SubtreeLibrary parse_subtree_library(const std::string& text, const std::string& where)
{
    const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) throw InvalidInput(where + ": not valid JSON");
    // "format" is checked to be a string before it is compared: json::value throws for
    // another type (the species preset's fuzz finding, docs/fuzzing.md).
    const auto format = j.is_object() ? j.find("format") : j.end();
    if (!j.is_object() || format == j.end() || !format->is_string() || format->get<std::string>() != "lobesketch-subtrees")
        throw InvalidInput(where + ": not a subtree library (missing \"format\": \"lobesketch-subtrees\")");
    if (!j.contains("version") || !j["version"].is_number_integer() || j["version"].get<int>() != 1)
        throw InvalidInput(where + ": unsupported subtree library version (this program reads version 1)");
    auto list = j.find("subtrees");
    if (list == j.end() || !list->is_array() || list->empty())
        throw InvalidInput(where + ": \"subtrees\" must be a non-empty array");
    if (list->size() > kMaxSubtrees) throw InvalidInput(where + ": more than 256 subtrees");
    SubtreeLibrary lib;
    std::set<std::string> names;
    for (std::size_t i = 0; i < list->size(); ++i) {
        const json& s = (*list)[i];
        const std::string w = where + ": subtrees[" + std::to_string(i) + "]";
        if (!s.is_object()) throw InvalidInput(w + ": expected an object");
        Subtree st;
        if (!s.contains("name") || !s["name"].is_string() || s["name"].get<std::string>().empty())
            throw InvalidInput(w + ".name: expected a non-empty string");
        st.name = s["name"].get<std::string>();
        if (!names.insert(st.name).second) throw InvalidInput(w + ": duplicate name '" + st.name + "'");
        const json* nodes = s.contains("nodes") ? &s["nodes"] : nullptr;
        const json* parents = s.contains("parents") ? &s["parents"] : nullptr;
        if (!nodes || !nodes->is_array() || !parents || !parents->is_array() || nodes->size() != parents->size())
            throw InvalidInput(w + ": \"nodes\" and \"parents\" must be arrays of the same length");
        if (nodes->size() < 2 || nodes->size() > kMaxSubtreeNodes)
            throw InvalidInput(w + ": a subtree has 2 to 64 nodes");
        for (std::size_t k = 0; k < nodes->size(); ++k) {
            const json& p = (*nodes)[k];
            if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number())
                throw InvalidInput(w + ".nodes[" + std::to_string(k) + "]: expected [x, y, z]");
            const glm::vec3 v(p[0].get<float>(), p[1].get<float>(), p[2].get<float>());
            if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z) || glm::length(v) > 100.0f)
                throw InvalidInput(w + ".nodes[" + std::to_string(k) + "]: not a finite coordinate");
            const json& q = (*parents)[k];
            if (!q.is_number_integer()) throw InvalidInput(w + ".parents: expected integers");
            const long long parent = q.get<long long>();
            if (k == 0 ? parent != -1 : (parent < 0 || parent >= static_cast<long long>(k)))
                throw InvalidInput(w + ".parents[" + std::to_string(k) + "]: the root's parent is -1 and every other "
                                   "node's parent comes before it");
            st.nodes.push_back(v);
            st.parents.push_back(static_cast<int>(parent));
        }
        // The root sits on the growing node: move it to the origin, then scale to unit length.
        const glm::vec3 root = st.nodes[0];
        float extent = 0.0f;
        for (glm::vec3& v : st.nodes) {
            v -= root;
            extent = std::max(extent, glm::length(v));
        }
        if (extent < 1e-3f) throw InvalidInput(w + ": every node sits on the root");
        for (glm::vec3& v : st.nodes) v /= extent;
        lib.subtrees.push_back(std::move(st));
    }
    return lib;
}

const SubtreeLibrary& default_subtree_library()
{
    static const SubtreeLibrary lib = [] {
        for (const EmbeddedFile& f : embedded_growth_data())
            if (f.name == "subtrees.json") return parse_subtree_library(std::string(f.text), "subtrees.json");
        throw InvalidInput("subtrees.json: not compiled into this program");
    }();
    return lib;
}

std::vector<double> subtree_weights(const SubtreeLibrary& library, const std::map<std::string, double>& by_name)
{
    std::vector<double> w(library.subtrees.size(), by_name.empty() ? 1.0 : 0.0);
    for (const auto& [name, weight] : by_name) {
        bool found = false;
        for (std::size_t i = 0; i < library.subtrees.size(); ++i)
            if (library.subtrees[i].name == name) {
                w[i] = weight;
                found = true;
            }
        if (!found) throw InvalidInput("subtree_weights: no subtree named '" + name + "' in the library");
    }
    double total = 0.0;
    for (double x : w) total += x;
    if (!(total > 0.0)) throw InvalidInput("subtree_weights: every weight is 0");
    return w;
}

} // namespace lobe
