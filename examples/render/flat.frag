#version 450
// Flat shading for any rig, even one without normals (the glTF Fox): the face normal from
// the screen-space derivatives of the world position, as colour. Needs only world.position.
layout(location = 0) in vec3 world_position;
layout(location = 0) out vec4 COLOR;
void main() {
  vec3 n = normalize(cross(dFdx(world_position), dFdy(world_position)));
  COLOR = vec4(n * 0.5 + 0.5, 1.0);
}
