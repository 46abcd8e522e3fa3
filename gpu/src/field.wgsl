// Grid model of eq. (2) for a batch of fields, one pass per dispatch. The arithmetic of every pass is
// written to be the same f32 operations, in the same order, as the CPU backend (sim/src/field/grid.rs).
//
// Field f keeps two slots of n = nx * ny cells at vals[(2 f + slot) n ..]; the per-field plan entry of a
// pass says whether the field takes part and which slot it reads. Passes that ping-pong write the other
// slot; in-place passes write the slot they read.

struct PF {
    on: u32,
    src: u32,
    inj: i32,    // offset of the field's static injection map in `inj`, or -1
    coef: u32,   // offset of the field's Thomas coefficients in `coef`
    a: f32,
    b: f32,
    r: f32,
    c: f32,
};

struct Pass {
    index: u32,     // row of the plan (plan[index * nfields + f]) or first deposit of a round
    nfields: u32,
    nx: u32,
    ny: u32,
    groups_x: u32,  // workgroups along x of the dispatch (linear ids fold x and y)
    count: u32,     // deposits in the round
    cell: f32,
    _pad: u32,
};

struct Dep {
    field: u32,
    slot: u32,
    i0: u32,
    j0: u32,
    w: u32,
    h: u32,
    kind: u32,      // 0 disc, 1 cone, 2 gaussian
    _pad: u32,
    ax: f32,
    ay: f32,
    abx: f32,
    aby: f32,
    len2: f32,
    support: f32,
    param: f32,     // radius or sigma
    amount: f32,
};

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

// Backward-Euler x-solve, one thread per row (Thomas), fused with evaporation and injection.
@compute @workgroup_size(64)
fn xsolve(@builtin(global_invocation_id) gid: vec3<u32>) {
    let line = line_of(gid, P.ny);
    if (!line.on) { return; }
    let nx = P.nx;
    let first = line.i * nx;
    let s = line.s + first;
    let d = line.d + first;
    let e = line.e;
    let m = e.coef;
    let cp = e.coef + nx;
    var prev = 0.0;
    for (var i = 0u; i < nx; i = i + 1u) {
        var fv: f32;
        if (e.inj >= 0) {
            fv = exact(e.a * vals[s + i]) + exact(e.b * inj[u32(e.inj) + first + i]);
        } else {
            fv = exact(e.a * vals[s + i]);
        }
        let v = flush((fv + exact(e.r * prev)) * coef[m + i]);
        vals[d + i] = v;
        prev = v;
    }
    if (nx > 1u) {
        var i = nx - 1u;
        loop {
            i = i - 1u;
            vals[d + i] = flush(vals[d + i] + exact(coef[cp + i] * vals[d + i + 1u]));
            if (i == 0u) { break; }
        }
    }
}

// Backward-Euler y-solve, one thread per column.
@compute @workgroup_size(64)
fn ysolve(@builtin(global_invocation_id) gid: vec3<u32>) {
    let line = line_of(gid, P.nx);
    if (!line.on) { return; }
    let nx = P.nx;
    let ny = P.ny;
    let s = line.s + line.i;
    let d = line.d + line.i;
    let e = line.e;
    let m = e.coef + 2u * nx;
    let cp = m + ny;
    vals[d] = flush(vals[s] * coef[m]);
    for (var j = 1u; j < ny; j = j + 1u) {
        vals[d + j * nx] = flush((vals[s + j * nx] + exact(e.r * vals[d + (j - 1u) * nx])) * coef[m + j]);
    }
    if (ny < 2u) { return; }
    var j = ny - 1u;
    loop {
        j = j - 1u;
        vals[d + j * nx] = flush(vals[d + j * nx] + exact(coef[cp + j] * vals[d + (j + 1u) * nx]));
        if (j == 0u) { break; }
    }
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
