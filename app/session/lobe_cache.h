#pragma once
/// \file lobe_cache.h
/// What a session's lobes were built from last time, kept between rebuilds by a thread that
/// rebuilds them again and again (the interactive apps' regrowth worker). A lobe whose
/// strokes, stroke edits and settings did not change is not built again, and a lobe that
/// only gained strokes at the end of its list continues from its kept state: adding a
/// stroke to a 10-stroke lobe joins that one stroke and remeshes that one lobe, where a
/// rebuild from scratch joins all eleven strokes of every lobe and remeshes every lobe.
/// The lobes are byte for byte those of build_document_lobes without a cache: joining
/// strokes one at a time depends only on the strokes and their order (lobe.h), and
/// remeshing only on the surface and the options.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "app/session/lobe_document.h"

namespace lobe {

class LobeBuildCache {
public:
    LobeBuildCache();
    ~LobeBuildCache();
    LobeBuildCache(const LobeBuildCache&) = delete;
    LobeBuildCache& operator=(const LobeBuildCache&) = delete;

    /// Lobes the last build could take as they were (none changed) or continue (strokes added
    /// at the end), and lobes it built from scratch.
    struct Counts {
        std::size_t kept = 0, continued = 0, built = 0;
        /// Regions of the lobes remeshed by the last build, and regions it took as remeshed
        /// before (lobe_remesh.h): a stroke added remeshes only the regions it changed.
        std::size_t regions_remeshed = 0, regions_reused = 0;
    };
    const Counts& last_build() const { return counts_; }

    struct Impl;

private:
    friend std::vector<BuiltLobe> build_document_lobes(const Document&, std::vector<std::string>*, LobeBuildCache&);
    std::unique_ptr<Impl> impl_;
    Counts counts_;
};

/// What a kept lobe was built with: every setting of the lobes section, through the settings
/// table (settings_key), so a lobes setting added later is in it without more. A lobe whose
/// key changed is built again. (The input section does not matter: the strokes are in the
/// document as the input pipeline made them.)
std::string lobe_build_key(const Settings& settings);

/// build_document_lobes (lobe_document.h), keeping and reusing what `cache` holds of the last
/// build. The result and the warnings are those of a build without a cache.
std::vector<BuiltLobe> build_document_lobes(const Document& doc, std::vector<std::string>* warnings,
                                            LobeBuildCache& cache);

} // namespace lobe
