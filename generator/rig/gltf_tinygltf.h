// tinygltf with this project's configuration (no image decoding), for the glTF reader's
// translation units. The implementation is compiled once, in gltf_load.cpp.
#pragma once
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>
