// The project-wide vertex attribute locations of a GpuMesh
// (render/gl/gpu_mesh.h: kPositionLocation, kNormalLocation, kUvLocation);
// every mesh vertex shader includes this instead of declaring its own.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
