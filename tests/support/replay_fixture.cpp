#include "tests/support/replay_fixture.h"

#include <map>

#include "app/session/edit_hooks.h"
#include "input/pipeline.h"
#include "input/recording.h"
#include "app/session/session_builder.h"
#include "tests/support/test_paths.h"

namespace lobe::test {

Document replay_document(const std::string& name)
{
    const Recording rec = read_recording(source_path("recordings/" + name + ".lrec"));
    const InputResult r = run_input_pipeline(rec);
    SessionBuilder b(Document{}, EditPickOptions{}, meshing_edit_hooks());
    b.apply(r.actions);
    return b.take_document();
}

const ReplayedScene& replayed_scene(const std::string& name)
{
    static std::map<std::string, ReplayedScene> cache;
    auto it = cache.find(name);
    if (it != cache.end()) return it->second;
    ReplayedScene s;
    s.doc = replay_document(name);
    s.lobes = build_document_lobes(s.doc);
    return cache.emplace(name, std::move(s)).first->second;
}

} // namespace lobe::test
