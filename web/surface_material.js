// The viewer's one shader: texture / patches / distortion / checker / seams views, texture scale and
// rotation, wireframe and seam lines from barycentric coordinates (no extra geometry), and tile
// variants: when K variants of a self-tileable texture exist (`tailor tile --variants K`, all with
// identical borders), every tile cell of the UV plane picks one variant from a seeded random grid,
// so the repetition of a single tile disappears (thesis section 3.2, aperiodic tiling).
//
// Colours are written as they are (no colour-space conversion, textures are read as raw data),
// with the same light as the CPU preview (tailor render), so both pictures match.
import * as THREE from 'three';

export const kMaxVariants = 8;
export const kViews = ['texture', 'patches', 'distortion', 'checker', 'seams'];

// Line colours of the seams view (display values, unlit): visible seams, invisible seams (the
// texture continues across them), mesh borders.
export const kSeamColors = { visible: [0.86, 0.08, 0.08], invisible: [0.05, 0.62, 0.16], border: [0.35, 0.35, 0.38] };
// tailor edit: the tint of faces marked as seam faces.
export const kMarkedColor = [1.0, 0.55, 0.0];
const glslColor = (c) => `vec3(${c.map((x) => x.toFixed(3)).join(', ')})`;

// What the vertex shader hands to the fragment shader (both must declare the same).
const varyings = /* glsl */ `
varying vec3 vNormal;
varying vec4 vTangent;
varying vec2 vUv;
varying vec3 vBary;
varying vec3 vSeam;
varying vec3 vSeamClass;
varying vec3 vPatch;
varying float vStretch;
varying float vMarked;
`;

const vertexShader = /* glsl */ `
attribute vec3 bary;
attribute vec3 seam;
attribute vec3 seamClass;
attribute vec3 patchColor;
attribute float stretch;
attribute vec4 fileTangent;  // the file's TANGENT (xyz, handedness w); zero when it has none
attribute float marked;      // tailor edit: 1 on the faces the user marked as seam faces (0 when absent)
${varyings}
void main() {
  vNormal = normalize(normalMatrix * normal);
  vTangent = vec4(mat3(modelViewMatrix) * fileTangent.xyz, fileTangent.w);
  vUv = uv;
  vBary = bary;
  vSeam = seam;
  vSeamClass = seamClass;
  vPatch = patchColor;
  vStretch = stretch;
  vMarked = marked;
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
}
`;

function variantBranches() {
  let code = '';
  for (let k = 0; k < kMaxVariants; ++k) {
    code += `    if (k == ${k}u) return textureGrad(variant${k}, f, dx, dy).rgb;\n`;
  }
  return code;
}

function variantUniforms() {
  let code = '';
  for (let k = 0; k < kMaxVariants; ++k) code += `uniform sampler2D variant${k};\n`;
  return code;
}

const fragmentShader = /* glsl */ `
uniform int mode;
uniform sampler2D map;
uniform bool hasMap;
uniform sampler2D normalMap;
uniform bool hasNormalMap;
uniform sampler2D occlusionMap;
uniform bool hasOcclusionMap;
${variantUniforms()}
uniform int variantCount;
uniform uint variantSeed;
uniform float uvScale;
uniform float uvRotation;
uniform float checkerSquares;
uniform float distortionRange;
uniform bool wireframe;
uniform bool showSeams;
uniform bool showMarked;
${varyings}
// Moreland's cool-to-warm end points, through light grey; t in [-1, 1].
vec3 coolWarm(float t) {
  t = clamp(t, -1.0, 1.0);
  vec3 mid = vec3(0.865);
  return t < 0.0 ? mix(mid, vec3(0.230, 0.299, 0.754), -t) : mix(mid, vec3(0.706, 0.016, 0.150), t);
}

// A 2D integer hash (PCG-style mixing) of a tile cell and the seed: the random variant grid.
uint cellHash(ivec2 cell, uint seed) {
  uint h = uint(cell.x) * 1597334677u ^ uint(cell.y) * 3812015801u ^ seed * 2654435769u;
  h ^= h >> 16; h *= 2246822519u; h ^= h >> 13; h *= 3266489917u; h ^= h >> 16;
  return h;
}

vec3 sampleVariant(vec2 uv) {
  // Derivatives of the continuous coordinate: fract() would make mipmapping jump at cell borders.
  vec2 dx = dFdx(uv);
  vec2 dy = dFdy(uv);
  vec2 f = fract(uv);
  uint k = cellHash(ivec2(floor(uv)), variantSeed) % uint(variantCount);
${variantBranches()}  return vec3(1.0, 0.0, 1.0);
}

// Box-filtered checker (no aliasing when squares get small on screen).
float checker(vec2 p) {
  vec2 w = max(fwidth(p), vec2(1e-4));
  vec2 i = 2.0 * (abs(fract((p - 0.5 * w) / 2.0) - 0.5) - abs(fract((p + 0.5 * w) / 2.0) - 0.5)) / w;
  return 0.5 - 0.5 * i.x * i.y;
}

// 1 on the marked edges of the triangle (flags per opposite corner), fading over ~width pixels.
float edgeLine(vec3 flags, float width) {
  vec3 d = fwidth(vBary);
  vec3 a = smoothstep(d * (width - 1.0), d * width, vBary);
  vec3 e = mix(vec3(1.0), a, flags);
  return 1.0 - min(min(e.x, e.y), e.z);
}

// Flags (per opposite corner) of the edges of seam class c (mesh_data.js: 1 invisible, 2 visible, 3 border).
vec3 seamFlags(float c) {
  return vec3(equal(floor(vSeamClass + 0.5), vec3(c)));
}

void main() {
  vec3 n = normalize(vNormal);
  float c = cos(uvRotation), s = sin(uvRotation);
  vec2 uv = mat2(c, s, -s, c) * vUv * uvScale;
  if (mode == 0 && hasNormalMap && dot(vTangent.xyz, vTangent.xyz) > 1e-8) {
    // glTF normal map (GL convention): the file's tangent frame; the panel's rotation turns the
    // texture, so the map's xy turn back with it.
    vec3 t = normalize(vTangent.xyz - n * dot(n, vTangent.xyz));
    vec3 b = cross(n, t) * (vTangent.w < 0.0 ? -1.0 : 1.0);
    vec3 m = texture2D(normalMap, uv).xyz * 2.0 - 1.0;
    m.xy = mat2(c, -s, s, c) * m.xy;
    n = normalize(t * m.x + b * m.y + n * m.z);
  }
  if (!gl_FrontFacing) n = -n;
  float diffuse = max(dot(n, normalize(vec3(-0.35, 0.55, 0.76))), 0.0);
  // The file's occlusion map scales the ambient light only (glTF: indirect light).
  float ambient = mode == 0 && hasOcclusionMap ? 0.36 * texture2D(occlusionMap, uv).r : 0.36;
  float light = ambient + 0.72 * diffuse;

  vec3 base;
  if (mode == 0) {
    if (variantCount > 0) base = sampleVariant(uv);
    else if (hasMap) base = texture2D(map, uv).rgb;
    else base = mix(vec3(150.0 / 255.0), vec3(205.0 / 255.0), checker(uv * 8.0));
  } else if (mode == 1) {
    base = vPatch;
  } else if (mode == 2) {
    base = coolWarm(vStretch / distortionRange);
  } else if (mode == 3) {
    base = mix(vec3(35.0, 35.0, 40.0) / 255.0, vec3(240.0 / 255.0), checker(uv * checkerSquares));
  } else {
    base = vec3(0.84);  // seams: a light neutral surface under the coloured lines
  }
  vec3 color = min(base * light, vec3(1.0));
  if (wireframe) color = mix(color, vec3(0.08), 0.75 * edgeLine(vec3(1.0), 1.5));
  if (mode == 1 && showSeams) color = mix(color, vec3(0.08, 0.08, 0.11), edgeLine(vSeam, 2.0));
  if (mode == 4) {
    // Each side of an edge draws its half, so a seam line is about twice this width on screen.
    color = mix(color, ${glslColor(kSeamColors.border)}, edgeLine(seamFlags(3.0), 1.2));
    color = mix(color, ${glslColor(kSeamColors.invisible)}, edgeLine(seamFlags(1.0), 2.0));
    color = mix(color, ${glslColor(kSeamColors.visible)}, edgeLine(seamFlags(2.0), 2.0));
  }
  if (showMarked && vMarked > 0.5) color = mix(color, ${glslColor(kMarkedColor)}, 0.5);
  gl_FragColor = vec4(color, 1.0);
}
`;

/** Shader material; `state` fields are copied into uniforms by updateSurfaceMaterial. */
export function createSurfaceMaterial() {
  const uniforms = {
    mode: { value: 0 },
    map: { value: null },
    hasMap: { value: false },
    normalMap: { value: null },
    hasNormalMap: { value: false },
    occlusionMap: { value: null },
    hasOcclusionMap: { value: false },
    variantCount: { value: 0 },
    variantSeed: { value: 1 },
    uvScale: { value: 1 },
    uvRotation: { value: 0 },
    checkerSquares: { value: 8 },
    distortionRange: { value: 2 },
    wireframe: { value: false },
    showSeams: { value: true },
    showMarked: { value: false },
  };
  for (let k = 0; k < kMaxVariants; ++k) uniforms[`variant${k}`] = { value: null };
  return new THREE.ShaderMaterial({ uniforms, vertexShader, fragmentShader, side: THREE.DoubleSide });
}

/** Applies the panel state ({view, scale, rotationDeg, wireframe, useVariants, seed, ...}). */
export function updateSurfaceMaterial(material, state, textures) {
  const u = material.uniforms;
  u.mode.value = Math.max(0, kViews.indexOf(state.view));
  // With variants turned off, the first variant repeats alone: the periodic tiling to compare with.
  const map = textures.variants.length > 0 ? textures.variants[0] : textures.map;
  u.map.value = map;
  u.hasMap.value = !!map;
  // The file's normal map shades the texture view (its tiles match the embedded colour map's).
  u.normalMap.value = textures.normalMap || textures.blank;
  u.hasNormalMap.value = !!textures.normalMap && state.normalMapping !== false;
  u.occlusionMap.value = textures.occlusionMap || textures.blank;
  u.hasOcclusionMap.value = !!textures.occlusionMap && state.normalMapping !== false;
  const variants = state.useVariants ? textures.variants : [];
  u.variantCount.value = variants.length;
  for (let k = 0; k < kMaxVariants; ++k) {
    // Unused samplers still need a texture bound: reuse any that exists.
    u[`variant${k}`].value = variants[k] || variants[0] || textures.map || textures.blank;
  }
  u.variantSeed.value = state.seed >>> 0;
  u.uvScale.value = state.scale;
  u.uvRotation.value = (state.rotationDeg * Math.PI) / 180;
  u.checkerSquares.value = state.checkerSquares;
  u.distortionRange.value = state.distortionRange;
  u.wireframe.value = state.wireframe;
  u.showSeams.value = state.seams;
  u.showMarked.value = state.showMarked === true;
}
