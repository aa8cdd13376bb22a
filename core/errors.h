#pragma once
/// \file errors.h
/// The small exception hierarchy every stage throws when a precondition breaks.
/// Messages are one line and, for files, start with the file name so the CLI can print
/// them unchanged.

#include <stdexcept>
#include <string>

namespace lobe {

/// `what` as one line: control characters a file put into a name or key quoted in the
/// message are escaped (\n, \t, \xHH), and a message longer than 1000 bytes is cut there
/// (at a character boundary) and ends in "…".
std::string one_line_message(const std::string& what);

/// Base of all Lobesketch errors. Every message is one line (one_line_message), whatever
/// the input quoted in it held.
class Error : public std::runtime_error {
public:
    explicit Error(const std::string& what) : std::runtime_error(one_line_message(what)) {}
    explicit Error(const char* what) : Error(std::string(what)) {}
};

/// Input data (a stroke, a setting, a parameter) is unusable.
class InvalidInput : public Error {
public:
    using Error::Error;
};

/// A file could not be read or written, or its content is malformed.
class FileError : public Error {
public:
    FileError(const std::string& path, const std::string& what) : Error(path + ": " + what) {}
};

/// A numerical method failed (singular system, no convergence).
class SolverError : public Error {
public:
    using Error::Error;
};

} // namespace lobe
