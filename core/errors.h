#pragma once
/// \file errors.h
/// The small exception hierarchy every stage throws when a precondition breaks.
/// Messages are one line and, for files, start with the file name so the CLI can print
/// them unchanged.

#include <stdexcept>
#include <string>

namespace lobe {

/// Base of all Lobesketch errors.
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
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
