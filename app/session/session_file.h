#pragma once
/// \file session_file.h
/// Loading a session document for use: the document reader (core/document.h) checks the
/// file's shape, this checks what only the layers above core know — that every tree's grower
/// exists and takes the parameters the file gives it (growth/grower.h). Every command and
/// app that opens a session goes through here.

#include <string>

#include "core/document.h"

namespace lobe {

/// Every tree's grower and parameters (checked_grower).
/// \throw InvalidInput naming the field, e.g. "trees[0].grower.name: unknown grower …".
void check_document_growers(const Document& doc);

/// load_document, then check_document_growers.
/// \throw FileError with a one-line reason naming the file.
Document load_session(const std::string& path);

/// Sets the grower of the scene's tree (scene_grower): the first tree's, adding a tree that
/// holds every lobe when the document has none. \throw InvalidInput as checked_grower.
void set_scene_grower(Document& doc, GrowerChoice choice);

} // namespace lobe
