// rths-logger: the logger participant process (writes log.lcm and signals.csv). Started by
// `rths run`; see docs/lockstep.md.
#include "participants/factory.h"

int main(int argc, char** argv) { return rths::participants::RoleMain("logger", argc, argv); }
