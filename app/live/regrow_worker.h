#pragma once
/// \file regrow_worker.h
/// Regrowth off the thread that draws frames: the interactive apps submit the document after
/// every change and pick up the newest finished tree when it is ready, so a frame never waits
/// for growth or geometry. Latest wins: a submission made while a regrowth runs replaces any
/// waiting one, and results of superseded submissions are dropped.

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "app/render/renderer.h"
#include "app/session/tree_pipeline.h"
#include "growth/tree_geometry.h"
#include "growth/wood.h"

namespace lobe {

struct RegrowResult {
    std::uint64_t generation = 0; ///< the submit() call this result answers
    bool grown = false;           ///< the tree was grown (else only the lobes were built)
    BuiltTree tree;
    TreeGeometry geometry;
    /// The grown tree's wood, carbon and CO₂ (growth/wood.h, docs/wood-and-co2.md); zeros
    /// until grown.
    WoodEstimate wood;
    std::string error; ///< non-empty when the document could not be grown (one line)
    /// What the app draws of this result, when the worker was given a prepare hook: made on
    /// the worker's thread with the rest, so that taking a result costs a frame nothing.
    RenderScene scene;
    int scene_lod = -1; ///< the tree's level of detail `scene` was made for (-1: none made)
};

class RegrowWorker {
public:
    /// `prepare` (may be empty) runs on the worker's thread after each regrowth that worked,
    /// before the result is handed out: the place for the app's own derived data
    /// (RegrowResult::scene). An Error it throws becomes the result's error.
    explicit RegrowWorker(std::function<void(RegrowResult&)> prepare = {});
    ~RegrowWorker(); ///< stops the worker thread (a running regrowth finishes first)
    RegrowWorker(const RegrowWorker&) = delete;
    RegrowWorker& operator=(const RegrowWorker&) = delete;

    /// Queues `doc` for regrowth and returns its generation number (1, 2, …). Never blocks on
    /// growth. With `grow_tree` false only the lobes are built (the result's tree has lobes,
    /// no growth, and its geometry no LOD): the sketching stages before the tree is grown.
    std::uint64_t submit(Document doc, bool grow_tree = true);
    /// True while a submission waits for the worker to start on it (a newer one would replace
    /// it): the interactive apps' drag previews are not made then.
    bool has_waiting();
    /// The newest finished result newer than the last one taken, if any. Never blocks on growth.
    std::optional<RegrowResult> take();
    /// Waits until the result of `generation` (or a newer one) is ready; for tests and batch use.
    RegrowResult wait_for(std::uint64_t generation);

private:
    void run();

    std::function<void(RegrowResult&)> prepare_;
    std::mutex mutex_;
    std::condition_variable wake_, done_;
    std::optional<Document> pending_;
    bool pending_grow_ = true;
    std::uint64_t submitted_ = 0, pending_generation_ = 0;
    std::optional<RegrowResult> ready_;
    bool stop_ = false;
    std::thread thread_;
};

} // namespace lobe
