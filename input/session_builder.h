#pragma once
/// \file session_builder.h
/// Applies the actions derived from raw input to a session document: completed strokes are
/// added (lobe strokes to the current lobe, "new lobe" starts another), drags become edit
/// operations, undo/redo walk the history of those changes.

#include <vector>

#include "core/document.h"
#include "input/pipeline.h"

namespace lobe {

class SessionBuilder {
public:
    /// A lobe stroke whose points all stay farther than this (or half the lobe's radius,
    /// when larger) from every lobe's strokes starts a new lobe.
    static constexpr double kJoinDistanceM = 0.10;

    explicit SessionBuilder(Document doc = {});

    /// Applies one action; returns true when the document changed.
    bool apply(const InputAction& action);
    void apply(const std::vector<InputAction>& actions);

    const Document& document() const { return doc_; }
    Document take_document() { return std::move(doc_); }

private:
    void add_stroke(const Stroke& stroke);
    Document doc_;
    bool new_lobe_pending_ = false;
    std::vector<Document> undo_, redo_;
    std::int64_t next_edit_id_ = 1;
    std::int64_t next_lobe_id_ = 1;
};

} // namespace lobe
