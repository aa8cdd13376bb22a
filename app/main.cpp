#include "app/cli.h"

int main(int argc, char** argv) { return lobe::run_cli(argc, argv); }
