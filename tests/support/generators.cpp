// Generators of valid quad surfaces (see generators.h).
#include "support/generators.h"
