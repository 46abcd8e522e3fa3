// Grid model of eq. (2) for a batch of fields, one pass per dispatch. The arithmetic of every pass is
// written to be the same f32 operations, in the same order, as the CPU backend (sim/src/field/grid.rs).
//
// Field f keeps two slots of n = nx * ny cells at vals[(2 f + slot) n ..]; the per-field plan entry of a
// pass says whether the field takes part and which slot it reads. Passes that ping-pong write the other
// slot; in-place passes write the slot they read.

// The structs `PF`, `Pass` and `Dep` go in place of the marker below: `shader_struct!` writes them
// from the Rust structs they are (`PlanEntry`, `PassUniform` in grids/record.rs, `DepRecord` in
// grids/deposit.rs).
//STRUCTS//

@group(0) @binding(0) var<storage, read_write> vals: array<f32>;
@group(0) @binding(1) var<storage, read> plan: array<PF>;
@group(0) @binding(2) var<uniform> P: Pass;
@group(0) @binding(3) var<storage, read> inj: array<f32>;
@group(0) @binding(4) var<storage, read> coef: array<f32>;
@group(0) @binding(5) var<storage, read> deps: array<Dep>;

// The GPU compilers fuse a multiply feeding an add into one FMA (one rounding instead of two), which
// the CPU does not do; a select on a uniform that is always false hides the product from that fusion,
// so the arithmetic stays that of the CPU.
fn exact(x: f32) -> f32 {
    return select(x, 0.0, P._pad != 0u);
}

fn linear_id(wg: vec3<u32>, lid: u32) -> u32 {
    return (wg.x + wg.y * P.groups_x) * 256u + lid;
}

fn entry(f: u32) -> PF {
    return plan[P.index * P.nfields + f];
}

// a Phi + b J (or a Phi without a map) at cell k of the source slot (the CPU's psi).
fn psi(e: PF, s: u32, k: u32) -> f32 {
    if (e.inj >= 0) {
        return exact(e.a * vals[s + k]) + exact(e.b * inj[u32(e.inj) + k]);
    }
    return e.a * vals[s + k];
}

// Work item i of `count` in a pass over field f (a cell, k = x + y nx, or a row or a column): the
// field's plan entry and the offsets of its slot the pass reads (s) and of the other one (d); `on` is
// false past the last item and for a field that sits the pass out (such a thread does nothing).
struct Item {
    i: u32,
    s: u32,
    d: u32,
    e: PF,
    on: bool,
};

fn item_of(i: u32, count: u32, f: u32) -> Item {
    if (i >= count) {
        var none: Item;
        none.on = false;
        return none;
    }
    let n = P.nx * P.ny;
    let e = entry(f);
    return Item(i, (2u * f + e.src) * n, (2u * f + 1u - e.src) * n, e, e.on != 0u);
}

// The cell that thread lid of workgroup wg of a per-cell pass takes.
fn cell_of(wg: vec3<u32>, lid: u32) -> Item {
    return item_of(linear_id(wg, lid), P.nx * P.ny, wg.z);
}

// The row or column (of `count`) that thread gid of a per-line pass takes.
fn line_of(gid: vec3<u32>, count: u32) -> Item {
    return item_of(gid.x + gid.y * P.groups_x * 64u, count, gid.z);
}

// Values at or below 1e-30, negative values and NaN become 0 after every pass, as on the CPU
// (`FLUSH_BELOW` in sim/src/field/grid.rs: no subnormals).
fn flush(v: f32) -> f32 {
    return select(0.0, v, v > 1e-30);
}

// Phi <- a Phi + b J, in place.
@compute @workgroup_size(256)
fn evaporate(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let cell = cell_of(wg, lid);
    if (!cell.on) { return; }
    let e = cell.e;
    let at = cell.s + cell.i;
    if (e.inj >= 0) {
        vals[at] = flush(psi(e, cell.s, cell.i));
    } else {
        vals[at] = flush(vals[at] * e.a);
    }
}

// One explicit step of the symmetric 5-point Laplacian on psi = a Phi + b J,
// dst = w c + r ((l + r) + (up + dn)); walls count as the cell itself (no flux).
@compute @workgroup_size(256)
fn explicit_step(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let cell = cell_of(wg, lid);
    if (!cell.on) { return; }
    let e = cell.e;
    let s = cell.s;
    let k = cell.i;
    let x = k % P.nx;
    let y = k / P.nx;
    let w = 1.0 - exact(4.0 * e.r);
    let c = psi(e, s, k);
    var l = c;
    var rt = c;
    var up = c;
    var dn = c;
    if (x > 0u) { l = psi(e, s, k - 1u); }
    if (x + 1u < P.nx) { rt = psi(e, s, k + 1u); }
    if (y + 1u < P.ny) { up = psi(e, s, k + P.nx); }
    if (y > 0u) { dn = psi(e, s, k - P.nx); }
    vals[cell.d + k] = flush(exact(w * c) + exact(e.r * (exact(l + rt) + exact(up + dn))));
}

// The paper's one-sided scheme, eq. (4), conservative reading: each cell sends s/2 right and s/2 up.
@compute @workgroup_size(256)
fn one_sided(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let cell = cell_of(wg, lid);
    if (!cell.on) { return; }
    let x = cell.i % P.nx;
    let y = cell.i / P.nx;
    let half = 0.5 * cell.e.r;
    var keep_v = 0.0;
    if (y + 1u < P.ny) { keep_v = half; }
    var keep_h = 0.0;
    if (x + 1u < P.nx) { keep_h = half; }
    let at = cell.s + cell.i;
    var v = exact(vals[at] * (exact(1.0 - keep_h) - keep_v));
    if (x > 0u) { v = v + exact(half * vals[at - 1u]); }
    if (y > 0u) { v = v + exact(half * vals[at - P.nx]); }
    vals[cell.d + cell.i] = flush(v);
}

// The backward-Euler solves: one thread per line (a row for the x-solve, a column for the y-solve)
// runs the Thomas algorithm with the CPU's coefficients. A line's sweep is a chain of dependent
// steps, so its cells go through workgroup memory in tiles: the 64 threads of a workgroup copy a tile
// of their 64 lines x SPAN cells between the field and `tile` together, in coalesced loads and stores
// all in flight at once, and each thread then sweeps its own line in the tile. A global load in every
// step of the chain would wait a memory latency per cell.
const LINES: u32 = 64u;    // lines a workgroup solves, one per thread
const SPAN: u32 = 32u;     // cells of each line a tile holds
const PITCH: u32 = 33u;    // a line's stride in `tile` (odd: the threads' rows fall in different banks)
var<workgroup> tile: array<f32, 2112>;   // LINES * PITCH
var<workgroup> down: array<f32, 32>;     // the tile's forward coefficients (1 / pivot), SPAN of them
var<workgroup> up: array<f32, 32>;       // and its back-substitution ones

// A solve's geometry for one workgroup: the field's slots, its lines [first, first + LINES) of `count`,
// `len` cells a line; cell c of line l sits at l * line_step + c * cell_step in a slot.
struct Solve {
    x: bool,     // the x-solve (lines are rows), else the y-solve
    e: PF,
    on: bool,
    s: u32,
    d: u32,
    first: u32,
    count: u32,
    len: u32,
    line_step: u32,
    cell_step: u32,
    m: u32,      // offset of the forward coefficients in `coef`
    cp: u32,     // and of the back-substitution ones
};

fn solve_of(wg: vec3<u32>, x: bool) -> Solve {
    let n = P.nx * P.ny;
    let e = entry(wg.z);
    let first = (wg.x + wg.y * P.groups_x) * LINES;
    let s = (2u * wg.z + e.src) * n;
    let d = (2u * wg.z + 1u - e.src) * n;
    if (x) {
        return Solve(true, e, e.on != 0u, s, d, first, P.ny, P.nx, P.nx, 1u, e.coef, e.coef + P.nx);
    }
    let m = e.coef + 2u * P.nx;
    return Solve(false, e, e.on != 0u, s, d, first, P.nx, P.ny, 1u, P.nx, m, m + P.ny);
}

// Thread lid's q-th cell of a tile copy (q < SPAN): its line and cell in the tile. The x-solve's
// neighbouring threads take neighbouring cells of a row, the y-solve's neighbouring columns: either
// way neighbouring addresses in the field.
fn copy_slot(v: Solve, lid: u32, q: u32) -> vec2<u32> {
    if (v.x) {
        return vec2<u32>(q * (LINES / SPAN) + lid / SPAN, lid % SPAN);
    }
    return vec2<u32>(lid, q);
}

// Whether line l, cell c0 + c exists; and its index in a slot.
fn in_field(v: Solve, l: u32, c0: u32, c: u32) -> bool {
    return v.on && v.first + l < v.count && c0 + c < v.len;
}

fn at(v: Solve, l: u32, c0: u32, c: u32) -> u32 {
    return (v.first + l) * v.line_step + (c0 + c) * v.cell_step;
}

// The right-hand side of cells [c0, c0 + SPAN) of the workgroup's lines into `tile`, and the
// tile's coefficients. The x-solve's is evaporation and injection fused in (the CPU's psi); the
// y-solve's the x-solve's result.
fn load_rhs(v: Solve, lid: u32, c0: u32) {
    for (var q = 0u; q < SPAN; q = q + 1u) {
        let lc = copy_slot(v, lid, q);
        if (in_field(v, lc.x, c0, lc.y)) {
            let k = at(v, lc.x, c0, lc.y);
            var fv = vals[v.s + k];
            if (v.x) {
                if (v.e.inj >= 0) {
                    fv = exact(v.e.a * fv) + exact(v.e.b * inj[u32(v.e.inj) + k]);
                } else {
                    fv = exact(v.e.a * fv);
                }
            }
            tile[lc.x * PITCH + lc.y] = fv;
        }
    }
    load_coefficients(v, lid, c0);
}

fn load_coefficients(v: Solve, lid: u32, c0: u32) {
    if (lid < SPAN && c0 + lid < v.len) {
        down[lid] = coef[v.m + c0 + lid];
        up[lid] = coef[v.cp + c0 + lid];
    }
}

// `tile` from / to the destination slot, cells [c0, c0 + SPAN).
fn load_solution(v: Solve, lid: u32, c0: u32) {
    for (var q = 0u; q < SPAN; q = q + 1u) {
        let lc = copy_slot(v, lid, q);
        if (in_field(v, lc.x, c0, lc.y)) {
            tile[lc.x * PITCH + lc.y] = vals[v.d + at(v, lc.x, c0, lc.y)];
        }
    }
    load_coefficients(v, lid, c0);
}

fn store(v: Solve, lid: u32, c0: u32) {
    for (var q = 0u; q < SPAN; q = q + 1u) {
        let lc = copy_slot(v, lid, q);
        if (in_field(v, lc.x, c0, lc.y)) {
            vals[v.d + at(v, lc.x, c0, lc.y)] = tile[lc.x * PITCH + lc.y];
        }
    }
}

// Thomas over the workgroup's lines, tile by tile: forward elimination (v_i = (f_i + r v_{i-1}) m_i),
// then back-substitution (v_i += c'_i v_{i+1}) from the far end, the same operations in the same
// order as the CPU's (sim/src/field/grid.rs). Barriers sit in uniform control flow: every thread of
// the workgroup runs every loop (a thread past the last line only copies nothing). The last tile
// stays in `tile` from elimination to substitution: it is stored once, after both.
fn thomas(v: Solve, lid: u32) {
    let mine = v.on && v.first + lid < v.count;
    let row = lid * PITCH;
    let tiles = (v.len + SPAN - 1u) / SPAN;
    var prev = 0.0;
    for (var t = 0u; t < tiles; t = t + 1u) {
        let c0 = t * SPAN;
        load_rhs(v, lid, c0);
        workgroupBarrier();
        if (mine) {
            let w = min(SPAN, v.len - c0);
            for (var c = 0u; c < w; c = c + 1u) {
                let val = flush((tile[row + c] + exact(v.e.r * prev)) * down[c]);
                tile[row + c] = val;
                prev = val;
            }
        }
        workgroupBarrier();
        if (t + 1u < tiles) {
            store(v, lid, c0);
        }
        workgroupBarrier();
    }
    // The last cell is final after elimination: substitution starts from it.
    var next = prev;
    var t = tiles;
    loop {
        if (t == 0u) { break; }
        t = t - 1u;
        let c0 = t * SPAN;
        if (t + 1u < tiles) {
            load_solution(v, lid, c0);
        }
        workgroupBarrier();
        if (mine) {
            var c = min(SPAN, v.len - c0);
            if (c0 + c == v.len) { c = c - 1u; }  // skip the last cell itself
            loop {
                if (c == 0u) { break; }
                c = c - 1u;
                let val = flush(tile[row + c] + exact(up[c] * next));
                tile[row + c] = val;
                next = val;
            }
        }
        workgroupBarrier();
        store(v, lid, c0);
        workgroupBarrier();
    }
}

// Backward-Euler x-solve, fused with evaporation and injection.
@compute @workgroup_size(64)
fn xsolve(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    thomas(solve_of(wg, true), lid);
}

// Backward-Euler y-solve.
@compute @workgroup_size(64)
fn ysolve(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    thomas(solve_of(wg, false), lid);
}

// Upwind advection by the field's Courant number c (|c| <= 1/2) along an axis of `len` cells, `stride`
// apart, on which the cell is the `i`th; no-flux walls.
fn advected(cell: Item, i: u32, len: u32, stride: u32) -> f32 {
    let s = cell.s;
    let k = cell.i;
    let c = cell.e.c;
    let old = vals[s + k];
    if (c > 0.0) {
        if (i == len - 1u) {
            return old + exact(c * vals[s + k - stride]);
        } else if (i == 0u) {
            return old * (1.0 - c);
        }
        return exact(old * (1.0 - c)) + exact(c * vals[s + k - stride]);
    }
    let ca = -c;
    if (i == 0u) {
        return old + exact(ca * vals[s + k + stride]);
    } else if (i == len - 1u) {
        return old * (1.0 - ca);
    }
    return exact(old * (1.0 - ca)) + exact(ca * vals[s + k + stride]);
}

// Upwind advection along x.
@compute @workgroup_size(256)
fn advect_x(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let cell = cell_of(wg, lid);
    if (!cell.on) { return; }
    vals[cell.d + cell.i] = flush(advected(cell, cell.i % P.nx, P.nx, 1u));
}

// Upwind advection along y.
@compute @workgroup_size(256)
fn advect_y(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let cell = cell_of(wg, lid);
    if (!cell.on) { return; }
    vals[cell.d + cell.i] = flush(advected(cell, cell.i / P.nx, P.ny, P.nx));
}

//KEXP//

fn kernel_weight(kind: u32, param: f32, dist: f32) -> f32 {
    let d = abs(dist);
    if (kind == 0u) {
        if (d <= param) { return 1.0; }
        return 0.0;
    }
    if (kind == 1u) {
        if (d < param) { return 1.0 - d / param; }
        return 0.0;
    }
    if (d <= 3.0 * param && param > 0.0) {
        return kexp(-d * d / (2.0 * param * param));
    }
    if (d == 0.0) { return 1.0; }
    return 0.0;
}

// One round of trail deposits: deposit P.index + wg.z adds amount * kernel(distance to its segment) to
// the cells of its bounding box. A round holds at most one deposit per field, so no two threads write
// the same cell; rounds run in order, which keeps the CPU's order of additions.
@compute @workgroup_size(256)
fn deposit(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    if (wg.z >= P.count) { return; }
    let dp = deps[P.index + wg.z];
    let k = linear_id(wg, lid);
    if (k >= dp.w * dp.h) { return; }
    let i = dp.i0 + k % dp.w;
    let j = dp.j0 + k / dp.w;
    let n = P.nx * P.ny;
    let px = (f32(i) + 0.5) * P.cell;
    let py = (f32(j) + 0.5) * P.cell;
    var t = 0.0;
    if (dp.len2 > 0.0) {
        t = clamp((exact((px - dp.ax) * dp.abx) + exact((py - dp.ay) * dp.aby)) / dp.len2, 0.0, 1.0);
    }
    let qx = px - (dp.ax + exact(dp.abx * t));
    let qy = py - (dp.ay + exact(dp.aby * t));
    let dist = sqrt(exact(qx * qx) + exact(qy * qy));
    if (dist <= dp.support) {
        let w = kernel_weight(dp.kind, dp.param, dist);
        if (w != 0.0) {
            let idx = (2u * dp.field + dp.slot) * n + j * P.nx + i;
            vals[idx] = vals[idx] + exact(dp.amount * w);
        }
    }
}
