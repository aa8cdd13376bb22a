#include "app/session/session_file.h"

#include "core/errors.h"
#include "growth/grower.h"

namespace lobe {

void check_document_growers(const Document& doc)
{
    for (std::size_t i = 0; i < doc.trees.size(); ++i)
        checked_grower(doc.trees[i].grower, "trees[" + std::to_string(i) + "].grower");
}

Document load_session(const std::string& path)
{
    Document doc = load_document(path);
    try {
        check_document_growers(doc);
    } catch (const InvalidInput& e) {
        throw FileError(path, e.what());
    }
    return doc;
}

void set_scene_grower(Document& doc, GrowerChoice choice)
{
    checked_grower(choice, "grower");
    if (doc.trees.empty()) {
        TreeInstance tree;
        tree.id = 1;
        tree.seed = doc.seed;
        doc.trees.push_back(std::move(tree));
    }
    doc.trees.front().grower = std::move(choice);
}

} // namespace lobe
