#include "growth/grower.h"

#include <array>

#include "core/errors.h"
#include "growth/lsystem/lsystem_grower.h"
#include "growth/selforg/selforg_grower.h"
#include "growth/subtree_library.h"

namespace lobe {

namespace {

/// The paper's growth (Zhang et al. 2021, §5.2): attractors on the lobes, clustered per node,
/// split by their angular spans, a library subtree per piece along V_A (growth/grow.h). Its
/// parameters are the session's growth settings (settings.growth, per-lobe overrides); it
/// takes none of its own.
class SubtreeGrower final : public Grower {
public:
    std::string_view name() const override { return kDefaultGrowerName; }
    std::string_view title() const override { return "Subtrees in lobes (Zhang et al. 2021, section 5)"; }
    int version() const override { return 1; }
    int panel_code() const override { return 0; }

    void check_params(const GrowerChoice& choice, const std::string& where) const override
    {
        if (choice.version > version())
            throw InvalidInput(where + ".version: " + std::to_string(choice.version) + " is newer than this build reads (" +
                               std::to_string(version()) + ")");
        if (!choice.params.empty())
            throw InvalidInput(where + ".params." + choice.params.begin()->first + ": the " + std::string(name()) +
                               " grower takes no parameters (its settings are settings.growth)");
    }

    GrowthResult grow(const GrowerInput& in) const override
    {
        return grow_tree(in.trunk_strokes, in.lobes, in.settings.growth, default_subtree_library(), in.seed,
                         in.max_tree_nodes);
    }
};

const SubtreeGrower kSubtrees;

} // namespace

std::span<const Grower* const> growers()
{
    // Made on first use: the list is ready whichever static initialiser asks first.
    static const std::array<const Grower*, 3> list{&kSubtrees, &lsystem_grower(), &self_organizing_grower()};
    return list;
}

const Grower* find_grower(std::string_view name)
{
    for (const Grower* g : growers())
        if (g->name() == name) return g;
    return nullptr;
}

std::string grower_names()
{
    const auto list = growers();
    std::string out;
    for (std::size_t i = 0; i < list.size(); ++i) {
        if (i > 0) out += i + 1 == list.size() ? " and " : ", ";
        out += list[i]->name();
    }
    return out;
}

const Grower& checked_grower(const GrowerChoice& choice, const std::string& where)
{
    const Grower* g = find_grower(choice.name);
    if (!g) throw InvalidInput(where + ".name: unknown grower \"" + choice.name + "\" (known: " + grower_names() + ")");
    g->check_params(choice, where);
    return *g;
}

} // namespace lobe
