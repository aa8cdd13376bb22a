#pragma once
/// \file edit_hooks.h
/// Connects the session builder (input/) with the meshing stage's view of edits, so that
/// drags pick strokes and lobes where the person sees them (earlier stroke edits and lobe
/// transforms applied) and an edit that would not apply is refused when it is made.
/// Imports (EditHooks::import_model) depend on where the meshes come from: the caller adds
/// that hook (replay: import_mesh_path beside the recording; the desktop: what it imported).

#include "core/errors.h"
#include "growth/species.h"
#include "app/session/session_builder.h"
#include "app/session/edit_ops.h"

namespace lobe {

inline EditHooks meshing_edit_hooks(const EditApplyOptions& options = {})
{
    EditHooks hooks;
    hooks.current_strokes = [options](const Document& doc) { return effective_strokes(doc, options); };
    hooks.check = [options](const Document& doc, const EditOperation& op) {
        return check_edit_operation(doc, op, options);
    };
    // A tree-wide species setting applies the preset as `--species` does.
    hooks.apply_species = [](Settings& s, const std::string& name) {
        try {
            apply_species(s, load_species(name));
            return std::string();
        } catch (const Error& e) {
            return std::string(e.what());
        }
    };
    // A lobe made from a mesh, moved, rotated and scaled as its transform operations say.
    hooks.model_in_stage = [options](const Document& doc, const LobeRecord& lobe) {
        TriangleMesh mesh = lobe.model ? lobe.model->mesh : TriangleMesh{};
        const glm::dmat4 t = lobe_transform(doc, lobe.id, doc.edits.size(), options);
        if (t != glm::dmat4(1.0)) transform_mesh(mesh, t);
        return mesh;
    };
    return hooks;
}

} // namespace lobe
