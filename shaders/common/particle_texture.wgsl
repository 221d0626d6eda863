// Particle data that neighbour loops read lives in rgba32float textures, 2^TEXEL_ROW_SHIFT
// texels wide: lavapipe fetches a texel for all lanes at once, where a storage-buffer load
// costs one scalar load per component per lane (measured about 8 times slower). The same
// constant as `gpu::state::TEXEL_ROW_SHIFT` (checked by solver/tests/shaders_validate.rs).

const TEXEL_ROW_SHIFT: u32 = 11u;

fn texel(i: u32) -> vec2<u32> {
    return vec2<u32>(i & ((1u << TEXEL_ROW_SHIFT) - 1u), i >> TEXEL_ROW_SHIFT);
}
