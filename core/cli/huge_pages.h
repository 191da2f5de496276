// Transparent huge pages for the commands that read a mesh or a packed dataset (why and what it
// gains: huge_pages.cpp). Linux with glibc only; elsewhere these do nothing.
#pragma once

namespace tetstream::cli {

// main() hands over its argv first: the program may start itself again with it.
void rememberCommandLine(char** argv);

// Called before a command reads its input: the program starts itself again with glibc's huge pages
// on and runs the same command line from the start. Returns where it does not (see the .cpp).
void useHugePages();

}  // namespace tetstream::cli
