#version 450
layout(location = 0) in vec3 vObjNormal;
layout(location = 1) in vec3 v_nrm;
layout(location = 2) in vec3 object_normal;
layout(location = 3) in vec3 NormalOS;
layout(location = 4) in vec3 out_normal_obj;
layout(location = 0) out vec4 color;
void main() { color = vec4(vObjNormal + v_nrm + object_normal + NormalOS + out_normal_obj, 1.0); }
