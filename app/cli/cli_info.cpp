// `lobesketch info REC`: what a recording holds; `lobesketch info SESSION.json`: its tree and
// the wood, carbon and CO₂ in it (growth/wood.h).
#include <cstdio>
#include <iostream>
#include <map>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "app/cli/cli.h"
#include "app/cli/cli_common.h"
#include "app/session/session_file.h"
#include "app/session/tree_pipeline.h"
#include "growth/wood.h"

namespace lobe::cli {

namespace {

struct HandStats {
    std::size_t frames = 0;
    std::size_t dropouts = 0;
    double lost_s = 0.0;
    double longest_dropout_s = 0.0;
};

// A drop-out is a stretch of frames in which a hand that had been tracked is not (inactive or
// its joints invalid), ended by the hand coming back.
HandStats hand_stats(const Recording& rec, int h)
{
    HandStats s;
    bool seen = false, lost = false;
    double lost_since = 0.0;
    for (const HandFrame& f : rec.frames) {
        const HandState& hs = f.hands[h];
        const bool ok = hs.active && hs[Joint::IndexTip].position_valid() && hs[Joint::Palm].position_valid();
        if (ok) {
            ++s.frames;
            if (lost) {
                const double d = f.time - lost_since;
                ++s.dropouts;
                s.lost_s += d;
                s.longest_dropout_s = std::max(s.longest_dropout_s, d);
                lost = false;
            }
            seen = true;
        } else if (seen && !lost) {
            lost = true;
            lost_since = f.time;
        }
    }
    return s;
}


/// A session's tree: its grower, nodes and wood estimate, as text or JSON.
void session_info(const std::string& path, bool as_json)
{
    const Document doc = load_session(path);
    const BuiltTree tree = build_document_tree(doc);
    for (const std::string& w : tree.warnings) warn(path + ": " + w);
    const WoodEstimate e = estimate_wood(tree.growth.tree, basic_wood_density(doc.settings.growth.species));
    const GrowerChoice& grower = scene_grower(doc);
    if (as_json) {
        const nlohmann::json j = {{"file", path},
                                  {"grower", grower.name},
                                  {"lobes", tree.lobes.size()},
                                  {"nodes", tree.growth.tree.size()},
                                  {"species", doc.settings.growth.species},
                                  {"wood", wood_json(e)}};
        std::cout << j.dump(2) << "\n";
        return;
    }
    std::printf("%s\n  grower %s, %zu lobe(s), %zu nodes, species %s\n", path.c_str(), grower.name.c_str(),
                tree.lobes.size(), tree.growth.tree.size(), doc.settings.growth.species.c_str());
    std::printf("  wood %.6g m3, dry biomass %.6g kg (%.0f kg/m3), carbon %.6g kg, CO2 %.6g kg (as sketched)\n",
                e.wood_volume_m3, e.dry_biomass_kg, e.density_kg_m3, e.carbon_kg, e.co2_kg);
}

} // namespace

void add_info_command(CLI::App& app, int& exit_code)
{
    auto* cmd = app.add_subcommand("info", "Summarise a recording (duration, frames per hand, drop-outs, events) or a "
                                           "session document (its tree, wood, carbon and CO2)");
    auto path = std::make_shared<std::string>();
    auto as_json = std::make_shared<bool>(false);
    cmd->add_option("REC", *path, "Recording (binary or text form), or session document (.json)")->required();
    cmd->add_flag("--json", *as_json, "Print the summary as JSON");
    cmd->callback([path, as_json, &exit_code] {
        // A session document by its content too (an autosave, a renamed session), not only by .json.
        if (lower_extension(*path) == ".json" || is_session_file(*path)) {
            session_info(*path, *as_json);
            exit_code = kExitOk;
            return;
        }
        Recording rec = load_recording_verbose(*path);
        const double duration = rec.frames.size() > 1 ? rec.frames.back().time - rec.frames.front().time : 0.0;
        std::map<std::string, std::size_t> events;
        for (const InputEvent& e : rec.events) {
            const char* kind = event_kind_name(e.kind);
            ++events[kind ? kind : "unknown"];
        }
        nlohmann::json j = {
            {"file", *path},
            {"version", rec.header.version},
            {"source", rec.header.source},
            {"device", rec.header.device},
            {"space", rec.header.space},
            {"nominal_rate_hz", rec.header.nominal_rate_hz},
            {"frames", rec.frames.size()},
            {"duration_s", duration},
            {"events", events},
            {"annotations", rec.annotations.size()},
        };
        for (int h = 0; h < kHandCount; ++h) {
            HandStats s = hand_stats(rec, h);
            j["hands"][hand_name(static_cast<Hand>(h))] = {{"frames", s.frames},
                                                           {"dropouts", s.dropouts},
                                                           {"lost_s", s.lost_s},
                                                           {"longest_dropout_s", s.longest_dropout_s}};
        }
        if (*as_json) {
            std::cout << j.dump(2) << '\n';
        } else {
            std::printf("%s\n  format version %d, source %s, device %s, space %s, nominal %.1f Hz\n", path->c_str(),
                        rec.header.version, rec.header.source.c_str(), rec.header.device.c_str(),
                        rec.header.space.c_str(), rec.header.nominal_rate_hz);
            const double rate = duration > 0 ? static_cast<double>(rec.frames.size() - 1) / duration : 0.0;
            std::printf("  %zu frames, %.2f s (%.1f Hz measured)\n", rec.frames.size(), duration, rate);
            for (int h = 0; h < kHandCount; ++h) {
                HandStats s = hand_stats(rec, h);
                std::printf("  %-5s hand: %zu tracked frames, %zu drop-outs (%.2f s lost, longest %.0f ms)\n",
                            hand_name(static_cast<Hand>(h)), s.frames, s.dropouts, s.lost_s,
                            s.longest_dropout_s * 1000.0);
            }
            std::printf("  events:");
            if (events.empty()) std::printf(" none");
            for (const auto& [k, n] : events) std::printf(" %zu %s", n, k.c_str());
            std::printf("\n  annotations: %zu\n", rec.annotations.size());
            std::fflush(stdout);
        }
        exit_code = kExitOk;
    });
}

} // namespace lobe::cli
