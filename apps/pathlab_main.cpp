// pathlab: the command-line entry point. Everything happens in apps/cli.
#include "apps/cli/cli.h"

int main(int argc, char** argv) { return pathlab::cli::run(argc, argv); }
