#pragma once
/// @file Owning handles of matio's C objects, for the io library's .mat reader and writer (an
/// internal header: it includes matio.h, which only rths_io sees).
#include <memory>

#include <matio.h>

namespace rths::io::matio {

/// Closes a .mat file with Mat_Close.
struct FileClose {
  void operator()(mat_t* m) const { Mat_Close(m); }
};
/// Frees a matio variable with Mat_VarFree.
struct VarFree {
  void operator()(matvar_t* v) const { Mat_VarFree(v); }
};
using File = std::unique_ptr<mat_t, FileClose>;
using Var = std::unique_ptr<matvar_t, VarFree>;

}  // namespace rths::io::matio
