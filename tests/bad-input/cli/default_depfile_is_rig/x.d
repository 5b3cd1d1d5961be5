# A small valid rig for the corpus: cases change one input and keep the others valid.
rig: tiny
deformers:
  bones: 4
  influences: 1
attributes:
  position: { format: float32x3, provides: vertex.position }
  normal:   { format: float32x3, provides: vertex.normal }
  joint:    { format: uint8x4, provides: "skin.joints[0]" }
uniforms:
  bones:     { type: mat4, array: bones, semantic: skin.bones }
  view_proj: { type: mat4, semantic: camera.view_projection }
