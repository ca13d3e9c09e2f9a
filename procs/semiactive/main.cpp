// rths-semiactive: the semiactive participant process. Started by `rths run` (the supervisor); see
// docs/lockstep.md for its inputs and outputs at step k.
#include "participants/factory.h"

int main(int argc, char** argv) { return rths::participants::RoleMain("semiactive", argc, argv); }
