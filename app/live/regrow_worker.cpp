#include "app/live/regrow_worker.h"

#include "app/export/tree_output.h"
#include "core/errors.h"
#include "app/session/lobe_cache.h"

#include <string>
#include <utility>
#include <vector>

namespace lobe {

RegrowWorker::RegrowWorker(std::function<void(RegrowResult&)> prepare)
    : prepare_(std::move(prepare)), thread_([this] { run(); })
{
}

RegrowWorker::~RegrowWorker()
{
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
}

std::uint64_t RegrowWorker::submit(Document doc, bool grow_tree)
{
    std::uint64_t generation = 0;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        generation = ++submitted_;
        pending_ = std::move(doc); // replaces a waiting submission: latest wins
        pending_generation_ = generation;
        pending_grow_ = grow_tree;
    }
    wake_.notify_one();
    return generation;
}

bool RegrowWorker::has_waiting()
{
    std::lock_guard<std::mutex> lock(mutex_);
    return pending_.has_value();
}

std::optional<RegrowResult> RegrowWorker::take()
{
    std::lock_guard<std::mutex> lock(mutex_);
    std::optional<RegrowResult> out = std::move(ready_);
    ready_.reset();
    return out;
}

RegrowResult RegrowWorker::wait_for(std::uint64_t generation)
{
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return ready_ && ready_->generation >= generation; });
    RegrowResult out = std::move(*ready_);
    ready_.reset();
    return out;
}

void RegrowWorker::run()
{
    // What the last regrowth built of each lobe: a lobe whose strokes did not change is not
    // built again, and one that gained a stroke joins only that stroke (app/session/lobe_cache.h).
    LobeBuildCache cache;
    for (;;) {
        Document doc;
        std::uint64_t generation = 0;
        bool grow = true;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            wake_.wait(lock, [&] { return stop_ || pending_.has_value(); });
            if (stop_) return;
            doc = std::move(*pending_);
            pending_.reset();
            generation = pending_generation_;
            grow = pending_grow_;
        }
        RegrowResult result;
        result.generation = generation;
        try {
            std::vector<std::string> warnings;
            std::vector<BuiltLobe> lobes = build_document_lobes(doc, &warnings, cache);
            if (grow) {
                // build_document_tree, with the kept lobes.
                result.tree = grow_document_tree(doc, std::move(lobes));
                warnings.insert(warnings.end(), result.tree.warnings.begin(), result.tree.warnings.end());
                result.tree.warnings = std::move(warnings);
                result.geometry = document_tree_geometry(doc, result.tree);
                result.wood = estimate_wood(result.tree.growth.tree, basic_wood_density(doc.settings.growth.species));
                result.grown = true;
            } else {
                result.tree.lobes = std::move(lobes);
                result.tree.warnings = std::move(warnings);
            }
            if (prepare_) prepare_(result);
        } catch (const Error& e) {
            result.error = e.what();
        } catch (const std::bad_alloc&) {
            result.error = "out of memory while regrowing the tree";
        }
        {
            std::lock_guard<std::mutex> lock(mutex_);
            // A result older than a waiting submission is superseded: drop it.
            if (!pending_ || pending_generation_ <= generation) ready_ = std::move(result);
        }
        done_.notify_all();
    }
}

} // namespace lobe
