#pragma once
// A shipped recording replayed into a session document (through the same input pipeline,
// session builder and edit hooks as `lobesketch replay`) and its lobes, for tests and
// benchmarks of what comes after. These read recordings/<name>.lrec as it is (a missing one
// throws FileError): a test asks for it with source_data (tests/support/test_data.h) first.
#include <string>
#include <vector>

#include "core/document.h"
#include "app/session/lobe_document.h"

namespace lobe::test {

/// recordings/<name>.lrec replayed into a document.
Document replay_document(const std::string& name);

struct ReplayedScene {
    Document doc;
    std::vector<BuiltLobe> lobes;
};
/// replay_document(name) and its lobes, built once per process.
const ReplayedScene& replayed_scene(const std::string& name);

} // namespace lobe::test
