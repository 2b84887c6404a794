// Compiled into every technique module by gilab_add_technique (cmake/GilabTechnique.cmake): the
// gilab version the module was built against, which gilab checks before using the module
// (core/technique/modules.h).
#include <string>

#include "core/technique/module_abi.h"

extern "C" __attribute__((visibility("default"))) const char* gilab_module_abi() {
    static const std::string abi = gilab::moduleAbi();
    return abi.c_str();
}
