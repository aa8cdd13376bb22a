#include "app/live/autosave.h"

#include <utility>

#include "core/errors.h"
#include "input/recording.h"

namespace lobe {

Document at_recording_position(const Document& doc, bool recorded, std::uint64_t frames, bool finished)
{
    Document out = doc;
    out.recording_frames = recorded ? std::optional<std::uint64_t>(frames) : std::nullopt;
    out.recording_finished = recorded && finished;
    return out;
}

AutosaveWriter::AutosaveWriter(std::string path) : path_(std::move(path)), thread_([this] { run(); }) {}

AutosaveWriter::~AutosaveWriter()
{
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
}

void AutosaveWriter::submit(Document doc)
{
    {
        std::lock_guard<std::mutex> lock(mutex_);
        pending_ = std::move(doc); // replaces a waiting one: newest wins
    }
    wake_.notify_one();
}

std::string AutosaveWriter::submit_after_change(RecordingWriter* recording, const Document& doc, std::uint64_t frames,
                                                bool finished, bool wait_for_disk)
{
    try {
        if (recording) recording->flush();
    } catch (const Error& e) {
        return e.what();
    }
    submit(at_recording_position(doc, recording != nullptr, frames, finished));
    if (wait_for_disk) wait();
    return {};
}

void AutosaveWriter::wait()
{
    std::unique_lock<std::mutex> lock(mutex_);
    idle_.wait(lock, [&] { return !pending_ && !busy_; });
}

std::vector<std::string> AutosaveWriter::take_failures()
{
    std::lock_guard<std::mutex> lock(mutex_);
    return std::exchange(failures_, {});
}

std::uint64_t AutosaveWriter::written() const
{
    std::lock_guard<std::mutex> lock(mutex_);
    return written_;
}

void AutosaveWriter::run()
{
    for (;;) {
        Document doc;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            wake_.wait(lock, [&] { return stop_ || pending_.has_value(); });
            // Stopping writes what is still waiting: it is the newest state of the session.
            if (!pending_) return;
            doc = std::move(*pending_);
            pending_.reset();
            busy_ = true;
        }
        std::string why;
        try {
            save_autosave(path_, doc);
        } catch (const Error& e) {
            why = e.what();
        } catch (const std::bad_alloc&) {
            why = path_ + ": out of memory while writing the autosave";
        } catch (const std::exception& e) {
            // Nothing may escape the thread (it would end the program): e.g. a JSON library
            // error for a name that is not UTF-8.
            why = one_line_message(path_ + ": " + e.what());
        }
        {
            std::lock_guard<std::mutex> lock(mutex_);
            busy_ = false;
            if (why.empty()) ++written_;
            else if (failures_.size() < 100) failures_.push_back(std::move(why));
        }
        idle_.notify_all();
    }
}

} // namespace lobe
