// Transparent huge pages for the commands that read a mesh or a packed dataset (why and what it
// gains: huge_pages.cpp). Linux with glibc only; elsewhere it does nothing.
#pragma once
#include <string>

namespace tetstream::cli {

// Called once, after the command line is parsed and before the command reads its input: the
// program starts itself again with argv and glibc's huge pages on (and, for a small input file,
// a heap that grows in large steps). Returns where it does not (see the .cpp), and in the
// restarted program.
void useHugePages(char** argv, const std::string& input);

}  // namespace tetstream::cli
