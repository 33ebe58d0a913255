// The one signal loader (texel/signal.hpp): every command and binding reads
// texture signals through load_signal().
#include "texel/error.hpp"
