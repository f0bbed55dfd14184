// Image textures; twin of image.rs (the CPU reference), which
// mirrors every function here operation for operation.
//
// All images of a scene live in one Rgba16Float atlas read with textureLoad,
// so filtering and wrapping are done here by hand, identically to the CPU.
// The including module declares the atlas; this file does not:
//
//     @group(0) @binding(8) var image_atlas: texture_2d<f32>;
//
// An image is described by one vec4f, `rect`: x, y of the top-left texel of
// its level 0 in the atlas, then its level-0 width and height, both powers
// of two. Its mip chain goes down to 1x1, so the level count follows from
// the size. Level 0 sits at (x, y); levels 1, 2, ... stack downwards in a
// column to its right (image_level_origin).
//
// uv has v up: (0, 0) is the bottom-left of the picture, texel row 0 its
// top. filter_mode: 0 nearest, 1 bilinear, 2 trilinear (uses lod); wrap: 0
// repeat, 1 clamp, 2 mirror. (`filter` is a reserved word in WGSL.)

// Number of mip levels of a chain whose level 0 is `size` texels.
fn image_level_count(size: vec2i) -> i32 {
    return i32(firstLeadingBit(u32(max(size.x, size.y)))) + 1;
}

// Size of mip level `k`: each side halved k times, at least 1.
fn image_level_size(size: vec2i, k: i32) -> vec2i {
    return max(size >> vec2u(u32(k)), vec2i(1));
}

// Top-left of mip level `k`, relative to level 0's top-left. Level j >= 1 is
// max(1, H >> j) rows tall, so level k starts below the k - 1 levels above
// it: H - (H >> (k - 1)) rows while those are at least 1 tall, plus one row
// for each level beyond where the height reached 1 (wide images).
fn image_level_origin(size: vec2i, k: i32) -> vec2i {
    if k == 0 {
        return vec2i(0);
    }
    let halvings = min(k - 1, i32(countTrailingZeros(u32(size.y))));
    return vec2i(size.x, size.y - (size.y >> u32(halvings)) + (k - 1 - halvings));
}

// Texel index `i` of a row or column of `n` texels, wrapped into [0, n - 1].
// `n` is a power of two, so a positive modulo is a mask (two's complement
// makes it right for negative `i` too): the same as the CPU's rem_euclid,
// without the integer divisions llvmpipe does lane by lane.
fn image_wrap(i: i32, n: i32, wrap: u32) -> i32 {
    if wrap == 1u {
        return clamp(i, 0, n - 1);
    }
    if wrap == 2u {
        let period = 2 * n;
        let m = i & (period - 1);
        return select(m, period - 1 - m, m >= n);
    }
    return i & (n - 1);
}

// Continuous texel coordinates of uv on a level of `size` texels (texel
// centres at +0.5; v up, rows down).
fn image_texel_coords(uv: vec2f, size: vec2i) -> vec2f {
    return vec2f(uv.x, 1.0 - uv.y) * vec2f(size);
}

fn image_fetch(rect: vec4f, k: i32, texel: vec2i) -> vec4f {
    let origin = vec2i(rect.xy) + image_level_origin(vec2i(rect.zw), k);
    return textureLoad(image_atlas, origin + texel, 0);
}

fn image_nearest(rect: vec4f, uv: vec2f, wrap: u32) -> vec4f {
    let size = vec2i(rect.zw);
    let i = vec2i(floor(image_texel_coords(uv, size)));
    return image_fetch(rect, 0, vec2i(image_wrap(i.x, size.x, wrap), image_wrap(i.y, size.y, wrap)));
}

fn image_bilinear(rect: vec4f, k: i32, uv: vec2f, wrap: u32) -> vec4f {
    let size = image_level_size(vec2i(rect.zw), k);
    let p = image_texel_coords(uv, size) - 0.5;
    let base = floor(p);
    let f = p - base;
    let i = vec2i(base);
    let x0 = image_wrap(i.x, size.x, wrap);
    let x1 = image_wrap(i.x + 1, size.x, wrap);
    let y0 = image_wrap(i.y, size.y, wrap);
    let y1 = image_wrap(i.y + 1, size.y, wrap);
    let upper = image_fetch(rect, k, vec2i(x0, y0)) * (1.0 - f.x) + image_fetch(rect, k, vec2i(x1, y0)) * f.x;
    let lower = image_fetch(rect, k, vec2i(x0, y1)) * (1.0 - f.x) + image_fetch(rect, k, vec2i(x1, y1)) * f.x;
    return upper * (1.0 - f.y) + lower * f.y;
}

// The image described by `rect` at `uv`. Nearest and bilinear read level 0;
// trilinear blends the two levels around `lod` (clamped to the chain). The
// generated texture code calls the filter's own function with the wrap as a
// literal, so a shader holds only the filtering it uses (every branch costs
// on SIMD); this switch serves the compute harness.
fn image_sample(rect: vec4f, uv: vec2f, filter_mode: u32, wrap: u32, lod: f32) -> vec4f {
    if filter_mode == 0u {
        return image_nearest(rect, uv, wrap);
    }
    if filter_mode == 1u {
        return image_bilinear(rect, 0, uv, wrap);
    }
    return image_trilinear(rect, uv, wrap, lod);
}

fn image_trilinear(rect: vec4f, uv: vec2f, wrap: u32, lod: f32) -> vec4f {
    let last = image_level_count(vec2i(rect.zw)) - 1;
    let l = clamp(lod, 0.0, f32(last));
    let base = floor(l);
    let k = i32(base);
    let t = l - base;
    let fine = image_bilinear(rect, k, uv, wrap);
    let coarse = image_bilinear(rect, min(k + 1, last), uv, wrap);
    return fine * (1.0 - t) + coarse * t;
}
