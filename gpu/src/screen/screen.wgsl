// The screen, eq. (1): I = clip(round(sum_j k_j Phi_j)) as 8-bit RGB, and the colour sensors' footprint
// sampling, with the same f32 operations as sim/src/screen.rs (`render`, `pixel_at`). Gaussian sources
// (eq. 5) are evaluated in f64 like the CPU when the device has SHADER_F64 (GAUSS_F64 below).

// The structs `Layer`, `Src` and `U` go in place of the marker below: `shader_struct!` writes them
// from the Rust structs they are (`LayerRec`, `SrcRec`, `Uni` in screen/mod.rs).
//STRUCTS//

@group(0) @binding(0) var<storage, read> vals: array<f32>;
@group(0) @binding(1) var<storage, read> layers: array<Layer>;
@group(0) @binding(2) var<storage, read> srcs: array<Src>;
@group(0) @binding(3) var<uniform> u: U;
@group(0) @binding(4) var<storage, read_write> outp: array<u32>;
@group(0) @binding(5) var<storage, read> points: array<vec2<f32>>;
@group(0) @binding(6) var<storage, read> qworld: array<u32>;

// The GPU compilers fuse a multiply feeding an add into one FMA (one rounding instead of two), which
// the CPU does not do; a select on a uniform that is always false hides the product from that fusion,
// so the arithmetic stays that of the CPU.
fn exact(x: f32) -> f32 {
    return select(x, 0.0, u._pad != 0u);
}

// (i0, i1, t) for linear interpolation at fractional index f on n samples, clamped (CPU `lerp_index`).
struct Lerp {
    i0: u32,
    i1: u32,
    t: f32,
};

fn lerp_index(f: f32, n: u32) -> Lerp {
    if (n <= 1u || !(f > 0.0)) { return Lerp(0u, 0u, 0.0); }
    let mx = f32(n - 1u);
    if (f >= mx) { return Lerp(n - 1u, n - 1u, 0.0); }
    let i0 = min(u32(floor(f)), n - 2u);
    return Lerp(i0, i0 + 1u, f - f32(i0));
}

fn grid_value(off: u32, x: f32, y: f32) -> f32 {
    let nx = u.nx;
    let lx = lerp_index(x / u.cell - 0.5, nx);
    let ly = lerp_index(y / u.cell - 0.5, u.ny);
    let r0 = off + ly.i0 * nx;
    let r1 = off + ly.i1 * nx;
    let lo = vals[r0 + lx.i0] + exact((vals[r0 + lx.i1] - vals[r0 + lx.i0]) * lx.t);
    let hi = vals[r1 + lx.i0] + exact((vals[r1 + lx.i1] - vals[r1 + lx.i0]) * lx.t);
    return lo + exact((hi - lo) * ly.t);
}

//GAUSS//

fn layer_value(l: Layer, x: f32, y: f32) -> f32 {
    if (l.kind == 0u) { return grid_value(l.offset, x, y); }
    var s = 0.0;
    for (var i = 0u; i < l.count; i = i + 1u) {
        s = s + gauss(srcs[l.offset + i], x, y, l.time);
    }
    return s;
}

// clip(round(level)) to 0..255, round half away from zero, NaN to 0 (CPU `to_level`).
fn to_level(a: f32) -> u32 {
    if (!(a > 0.0)) { return 0u; }
    if (a >= 255.0) { return 255u; }
    let t = trunc(a);
    var r = t;
    if (a - t >= 0.5) { r = t + 1.0; }
    return u32(r);
}

fn compose(first: u32, x: f32, y: f32) -> vec3<u32> {
    var a0 = 0.0;
    var a1 = 0.0;
    var a2 = 0.0;
    for (var j = 0u; j < u.nlayers; j = j + 1u) {
        let l = layers[first + j];
        let v = layer_value(l, x, y);
        a0 = a0 + exact(l.k[0] * v);
        a1 = a1 + exact(l.k[1] * v);
        a2 = a2 + exact(l.k[2] * v);
    }
    return vec3<u32>(to_level(a0), to_level(a1), to_level(a2));
}

// One image pixel per thread, row 0 at the top (y = panel height), packed RGBA8.
@compute @workgroup_size(256)
fn render(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let k = (wg.x + wg.y * u.groups_x) * 256u + lid;
    if (k >= u.width * u.height) { return; }
    let col = k % u.width;
    let row = k / u.width;
    let x = (f32(col) + 0.5) * u.px;
    let y = exact(f32(u.height - 1u - row) * u.py) + exact(0.5 * u.py);
    let c = compose(u.world * u.nlayers, x, y);
    outp[k] = c.x | (c.y << 8u) | (c.z << 16u) | (255u << 24u);
}

fn pixel_centre(v: f32, size: f32, n: u32) -> f32 {
    var idx = 0.0;
    if (v == v) { idx = clamp(floor(v / size), 0.0, f32(max(n, 1u) - 1u)); }
    return (idx + 0.5) * size;
}

// The 8-bit levels of the screen pixel under point `p` (m), of the world whose layers start at `first`.
fn levels_under(first: u32, p: vec2<f32>) -> vec3<u32> {
    let x = pixel_centre(p.x, u.ps_x, u.res_x);
    let y = pixel_centre(p.y, u.ps_y, u.res_y);
    return compose(first, x, y);
}

// Sensor `s`'s sums of levels, red, green, blue.
fn put_sums(s: u32, sum: vec3<u32>) {
    outp[3u * s] = sum.x;
    outp[3u * s + 1u] = sum.y;
    outp[3u * s + 2u] = sum.z;
}

// One sensor per thread: the sum of the 8-bit levels of the pixels under its footprint points.
@compute @workgroup_size(64)
fn sense(@builtin(global_invocation_id) gid: vec3<u32>) {
    let s = gid.x + gid.y * u.groups_x * 64u;
    if (s >= u.count) { return; }
    let first = qworld[s] * u.nlayers;
    var sum = vec3<u32>(0u, 0u, 0u);
    for (var q = 0u; q < u.width; q = q + 1u) {
        sum = sum + levels_under(first, points[s * u.width + q]);
    }
    put_sums(s, sum);
}

// The footprint offsets of the sensors of `sense_centres`, `u.width` a set.
@group(0) @binding(7) var<storage, read> offsets: array<vec2<f32>>;

// One sensor per thread, given as its centre (`points[s]`) and its footprint's set of offsets
// (`qworld[s]`): its points are `offset + centre`, the f32 sums of the CPU's `sample_points`. Sensor
// `s` belongs to world `s / u.height`.
@compute @workgroup_size(64)
fn sense_centres(@builtin(global_invocation_id) gid: vec3<u32>) {
    let s = gid.x + gid.y * u.groups_x * 64u;
    if (s >= u.count) { return; }
    let first = (s / u.height) * u.nlayers;
    let c = points[s];
    let fset = qworld[s] * u.width;
    var sum = vec3<u32>(0u, 0u, 0u);
    for (var q = 0u; q < u.width; q = q + 1u) {
        sum = sum + levels_under(first, offsets[fset + q] + c);
    }
    put_sums(s, sum);
}
