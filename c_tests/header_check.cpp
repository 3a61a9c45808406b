// The public header compiles as strict ISO C++ (see header_check.inc).
#include "header_check.inc"
