// The CLI as a user meets it: help, JSON output, and clear errors with a nonzero exit on bad input.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { spawnSync } from 'node:child_process';
import { cli, cliWithEnv, cliPath, root, tempDir, packedHarmonic } from './helpers.mjs';

test('--help on the tool and every subcommand', () => {
  const top = cli('--help');
  assert.equal(top.status, 0);
  for (const sub of ['gen', 'pack', 'iso', 'info']) assert.match(top.stdout, new RegExp(sub));
  for (const [sub, opt] of [['gen', '--n'], ['pack', '--field'], ['iso', '--value'], ['info', '--json']]) {
    const r = cli(sub, '--help');
    assert.equal(r.status, 0, sub);
    assert.match(r.stdout, new RegExp(opt), `${sub} --help mentions ${opt}`);
  }
  assert.notEqual(cli().status, 0, 'no subcommand is an error');
  assert.notEqual(cli('frobnicate').status, 0);
});

test('gen, pack, info and iso work together and report JSON', () => {
  const { vtu, pack, dir } = packedHarmonic(12, 'harmonic12-lossless', ['--lossless']);
  const infoMesh = cli('info', vtu, '--json').json;
  assert.equal(infoMesh.vertices, 12 ** 3);
  assert.equal(infoMesh.tets, 11 ** 3 * 6);
  assert.equal(infoMesh.fields[0].name, 'harmonic');
  assert.ok(infoMesh.fields[0].max <= 1.0001 && infoMesh.fields[0].min < 0);
  assert.equal(infoMesh.validation.ok, true, JSON.stringify(infoMesh.validation.findings));

  const infoPack = cli('info', pack, '--json').json;
  assert.equal(infoPack.packed, true);
  assert.equal(infoPack.tets, infoMesh.tets);
  assert.equal(infoPack.format.formatVersion, 2);
  assert.ok(Number.isInteger(infoPack.format.nodes) && infoPack.format.nodes < infoPack.format.chunks, 'at most one node a split chunk');

  // Lossless: every chunk applied gives the input's surface exactly.
  const a = cli('iso', vtu, '--value', '0.2', '--json').json;
  const b = cli('iso', pack, '--value', '0.2', '--json').json;
  for (const k of ['triangles', 'vertices']) assert.equal(a[k], b[k], k);
  assert.ok(Math.abs(a.area - b.area) <= 1e-12 * a.area, 'same area up to summation order');
  assert.ok(a.triangles > 100 && a.area > 0 && a.ms >= 0);
  // The default 16-bit grid moves values by at most half a step: the area barely changes.
  const lossy = packedHarmonic(12, 'harmonic12-lossy').pack;
  const c = cli('iso', lossy, '--value', '0.2', '--json').json;
  assert.ok(Math.abs(c.area - a.area) < 1e-4 * a.area, `${c.area} vs ${a.area}`);
  // Coarser levels: the base mesh is 1% of the vertices, but at least 256 on a mesh this small.
  const base = cli('info', pack, '--chunks', '1', '--json').json;
  assert.ok(base.vertices === 256 && base.format.chunksApplied === 1, JSON.stringify(base));
  const half = cli('iso', pack, '--value', '0.2', '--fraction', '0.5', '--json').json;
  assert.ok(half.triangles > 0 && half.tets < a.tets);
  const unpacked = path.join(dir, 'half.vtu');
  const u = cli('unpack', pack, '--fraction', '0.5', '-o', unpacked, '--json');
  assert.equal(u.status, 0, u.stderr);
  assert.equal(cli('iso', unpacked, '--value', '0.2', '--json').json.triangles, half.triangles);
  assert.notEqual(cli('iso', vtu, '--value', '0', '--chunks', '1').status, 0, '--chunks needs a packed input');

  const ply = path.join(dir, 's.ply');
  const w = cli('iso', pack, '--value', '0.2', '-o', ply);
  assert.equal(w.status, 0);
  const header = fs.readFileSync(ply).subarray(0, 400).toString('latin1');
  assert.match(header, /^ply\nformat binary_little_endian 1.0/);
  assert.match(header, new RegExp(`element face ${a.triangles}`));
});

test('bad input gives a clear error and a nonzero exit, never a crash', () => {
  const dir = tempDir('bad');
  const { vtu } = packedHarmonic(4, 'badsrc');
  const good = fs.readFileSync(vtu);
  const write = (name, bytes) => { const p = path.join(dir, name); fs.writeFileSync(p, bytes); return p; };
  const ascii = (cells, points, offsets = '4', type = '10') => `<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
<UnstructuredGrid><Piece NumberOfPoints="4" NumberOfCells="1">
<Points><DataArray type="Float32" NumberOfComponents="3" format="ascii">${points}</DataArray></Points>
<Cells><DataArray type="Int32" Name="connectivity" format="ascii">${cells}</DataArray>
<DataArray type="Int32" Name="offsets" format="ascii">${offsets}</DataArray>
<DataArray type="UInt8" Name="types" format="ascii">${type}</DataArray></Cells>
<PointData><DataArray type="Float32" Name="f" format="ascii">0 1 2 3</DataArray></PointData>
</Piece></UnstructuredGrid></VTKFile>`;
  const okPoints = '0 0 0 1 0 0 0 1 0 0 0 1';
  const cases = [
    ['missing file', [path.join(dir, 'nope.vtu')], /nope\.vtu/],
    ['truncated', [write('trunc.vtu', good.subarray(0, good.length >> 1))], /./],
    ['wrong magic', [write('magic.vtu', Buffer.from('hello world, not xml'))], /./],
    ['unknown format', [write('mesh.obj', Buffer.from('v 0 0 0\nv 1 0 0\nf 1 2 3\n'))], /obj|format|extension/i],
    ['index out of range', [write('idx.vtu', ascii('0 1 2 99', okPoints))], /99|range/i],
    ['NaN coordinate', [write('nan.vtu', ascii('0 1 2 3', '0 0 0 nan 0 0 0 1 0 0 0 1'))], /nan|finite/i],
    ['no tetrahedra', [write('empty.vtu', ascii('0 1 2', okPoints, '3', '5'))], /tetra/i],
  ];
  for (const [what, args, msg] of cases) {
    for (const cmd of [['info'], ['iso', '--value', '0'], ['pack', '-o', path.join(dir, 'out')]]) {
      const r = cli(cmd[0], ...args, ...cmd.slice(1));
      assert.equal(r.signal, null, `${what}: ${cmd[0]} crashed`);
      assert.equal(r.status, 1, `${what}: ${cmd[0]} exit ${r.status} ${r.stderr}`);
      assert.match(r.stderr, /^tetstream: error: /, `${what}: ${cmd[0]}`);
      assert.match(r.stderr, msg, `${what}: ${cmd[0]}: ${r.stderr}`);
    }
  }
  const missing = cli('iso', vtu, '--value', '0', '--field', 'pressure', '--json');
  assert.equal(missing.status, 1);
  assert.match(missing.stderr, /pressure/);
  assert.match(missing.stderr, /harmonic/, 'lists the fields that exist');
  assert.equal(missing.json.error.status, 'missing-field');
});

test('the other input formats: notes on stdout, --q names the PLOT3D solution', () => {
  const fx = (name) => path.join(root, 'tests/fixtures/formats', name);
  const info = cli('info', fx('p3d_be.xyz'), '--json');
  assert.equal(info.status, 0, info.stderr);
  assert.match(info.json.inputFormat, /^PLOT3D grid \(C binary, big-endian, float/);
  assert.deepEqual(info.json.fields.map((f) => f.name), ['density', 'momentum_magnitude', 'energy', 'pressure']);
  assert.ok(info.json.notes.some((n) => /gamma = 1\.4/.test(n)), info.json.notes.join('\n'));
  assert.equal(info.json.tets, 72);

  const dir = tempDir('formats');
  const pack = cli('pack', fx('p3d_fortran_iblank.x'), '--q', fx('p3d_fortran_iblank.q'), '-o', path.join(dir, 'p'));
  assert.equal(pack.status, 0, pack.stderr);
  assert.match(pack.stdout, /^note: IBLANK: 1 points are blanked/m);
  assert.match(pack.stdout, /^  format    PLOT3D grid \(Fortran records/m);
  const wrong = cli('info', fx('p3d_be.xyz'), '--q', fx('p3d_two_blocks.q'));
  assert.equal(wrong.status, 1);
  assert.match(wrong.stderr, /not a PLOT3D Q file for this grid/);

  const tetgen = cli('info', fx('grid.ele'), '--json');
  assert.equal(tetgen.status, 0, tetgen.stderr);
  assert.equal(tetgen.json.tets, 48);
  const gmsh = cli('info', fx('mixed_41_ascii.msh'));
  assert.equal(gmsh.status, 0, gmsh.stderr);
  assert.match(gmsh.stdout, /note {6}split 2 hexahedra, 4 wedges, 12 pyramids into 48 tetrahedra/);
  assert.match(gmsh.stdout, /valid {5}no problems found/);
});

// XDMF and VTKHDF through the CLI (tests/fixtures/hpc, written by meshio and h5py): info lists the
// time steps and which one was read, --step and --time pick another, pack and iso read them.
test('XDMF and VTKHDF: info lists the steps, --step picks one, pack and iso read them', () => {
  const fx = (name) => path.join(root, 'tests/fixtures/hpc', name);
  const info = cli('info', fx('xdmf_series.xdmf'), '--json');
  assert.equal(info.status, 0, info.stderr);
  assert.deepEqual(info.json.steps, [0, 0.25, 0.5, 0.75].map((time, index) => ({ index, time })));
  assert.equal(info.json.stepRead, 3);
  assert.match(info.json.inputFormat, /^XDMF 3 \(HDF5 heavy data\), Tetrahedron, step 3 of 4/);
  assert.equal(info.json.tets, 48);
  const f = (json) => json.fields.find((x) => x.name === 'f');
  assert.ok(Math.abs(f(info.json).min - 7.5) < 1e-5 && Math.abs(f(info.json).max - 13.5) < 1e-5, JSON.stringify(f(info.json)));

  const first = cli('info', fx('xdmf_series.xdmf'), '--step', '0', '--json');
  assert.equal(first.status, 0, first.stderr);
  assert.equal(first.json.stepRead, 0);
  assert.ok(Math.abs(f(first.json).max - 6) < 1e-5);
  const near = cli('info', fx('vtkhdf_series.vtkhdf'), '--time', '0.6', '--json');
  assert.equal(near.status, 0, near.stderr);
  assert.equal(near.json.stepRead, 1);
  assert.ok(near.json.notes.some((n) => /read the nearest, step 1/.test(n)), near.json.notes.join('\n'));
  const past = cli('info', fx('xdmf_series.xdmf'), '--step', '9');
  assert.equal(past.status, 1);
  assert.match(past.stderr, /--step 9 does not exist; it has 4 time steps/);

  const dir = tempDir('hpc');
  const pack = cli('pack', fx('vtkhdf_parts.vtkhdf'), '-o', path.join(dir, 'p'), '--json');
  assert.equal(pack.status, 0, pack.stderr);
  assert.equal(pack.json.tets, 48);
  const iso = cli('iso', fx('xdmf_mixed.xdmf'), '--value', '5', '--field', 'f', '--json');
  assert.equal(iso.status, 0, iso.stderr);
  assert.ok(iso.json.triangles > 0);

  const escape = path.join(dir, 'escape.xdmf');
  fs.writeFileSync(escape, fs.readFileSync(fx('xdmf_grid.xdmf'), 'utf8').replace('xdmf_grid.h5:/data0', '/etc/passwd:/x'));
  const refused = cli('info', escape);
  assert.equal(refused.status, 1);
  assert.match(refused.stderr, /escape\.xdmf Grid 'Grid' Geometry .*'\/etc\/passwd' is an absolute path/);
});

// Exodus II and CGNS (tests/fixtures/hpc): info lists the time steps, --step and --time pick one,
// and pack + iso work on what was read.
test('Exodus II and CGNS: steps listed by info, --step/--time, pack and iso', () => {
  const fx = (name) => path.join(root, 'tests/fixtures/hpc', name);
  const info = cli('info', fx('exo_blocks.exo'), '--json');
  assert.equal(info.status, 0, info.stderr);
  assert.match(info.json.inputFormat, /^Exodus II \(netCDF 64-bit offset\), 6 element blocks/);
  assert.deepEqual(info.json.steps, [{ index: 0, time: 0 }, { index: 1, time: 0.5 }, { index: 2, time: 1 }]);
  assert.equal(info.json.stepRead, 2);
  assert.equal(info.json.tets, 960);
  const temperature = (j) => j.fields.find((f) => f.name === 'temperature');
  assert.equal(temperature(info.json).max, 17, 'the last step: x + 2y + 3z + 10 at (2, 1, 1)');
  const first = cli('info', fx('exo_blocks.exo'), '--step', '0', '--json');
  assert.equal(first.json.stepRead, 0);
  assert.equal(temperature(first.json).max, 7);
  const near = cli('info', fx('exo_blocks.exo'), '--time', '0.6', '--json');
  assert.equal(near.json.stepRead, 1);
  const text = cli('info', fx('exo_blocks.exo'));
  assert.match(text.stdout, /^ {2}steps {5}3, read step 2 \(t = 1\)$/m);
  const past = cli('info', fx('exo_blocks.exo'), '--step', '7');
  assert.equal(past.status, 1);
  assert.match(past.stderr, /--step 7 does not exist; it has 3 time steps/);

  const dir = tempDir('hpc');
  const pack = cli('pack', fx('exo_blocks.exo'), '--step', '1', '--field', 'temperature', '-o', path.join(dir, 'exo'), '--json');
  assert.equal(pack.status, 0, pack.stderr);
  assert.equal(pack.json.tets, 960);
  const iso = cli('iso', path.join(dir, 'exo'), '--value', '8', '--json');
  assert.equal(iso.status, 0, iso.stderr);
  assert.ok(iso.json.triangles > 0 && iso.json.area > 0, JSON.stringify(iso.json));
  // The same surface from the file itself at that step (the pack is within half a grid step).
  const direct = cli('iso', fx('exo_blocks.exo'), '--step', '1', '--field', 'temperature', '--value', '8', '--json');
  assert.equal(direct.status, 0, direct.stderr);
  assert.ok(Math.abs(direct.json.area - iso.json.area) < 1e-3 * direct.json.area, `${direct.json.area} vs ${iso.json.area}`);

  const cgns = cli('pack', fx('cgns_structured.adf.cgns'), '-o', path.join(dir, 'cgns'));
  assert.equal(cgns.status, 0, cgns.stderr);
  assert.match(cgns.stdout, /^ {2}format {4}CGNS \(ADF\), base 'Base', 2 structured zones$/m);
  const poly = cli('info', fx('cgns_polyhedra.cgns'), '--json');
  assert.equal(poly.status, 1);
  assert.match(poly.stderr, /NFACE_n cells \(polyhedra given by their faces\) are not read/);
  assert.equal(poly.stdout.includes('Warning'), false, 'library warnings stay off stdout');
});

// Partitioned output (tests/fixtures/partitioned, written by VTK): info says what was read, and a
// pack of the pieces has the isosurface of the whole mesh.
test('partitioned VTK output: info, pack and iso as of the whole mesh', () => {
  const fx = (name) => path.join(root, 'tests/fixtures/partitioned', name);
  const info = cli('info', fx('ghost.pvtu'), '--json');
  assert.equal(info.status, 0, info.stderr);
  assert.match(info.json.inputFormat,
    /^parallel VTK \(\.pvtu\), 3 pieces, 392 ghost cells dropped, 50 interface points welded by coordinates; pieces: VTK XML UnstructuredGrid/);
  assert.equal(info.json.vertices, 112);
  assert.equal(info.json.tets, 324);
  assert.equal(info.json.validation.boundaryFaces, 180);
  assert.deepEqual(info.json.fields.map((f) => f.name), ['T', 'S', 'v_magnitude', 'region']);
  const ids = cli('info', fx('ids.pvtu'), '--json');
  assert.match(ids.json.inputFormat, /4 pieces, 76 interface points welded by GlobalIds/);
  const text = cli('info', fx('disagree.pvtu'));
  assert.match(text.stdout, /note {6}field 'T': 3 of 26 interface points disagree between pieces \(largest difference 0\.5\)/);

  const dir = tempDir('partitioned');
  for (const listing of ['ghost.pvtu', 'blocks.vtm', 'legacy.pvtk', 'petsc.vtu']) {
    const out = path.join(dir, listing.replace('.', '-'));
    const pack = cli('pack', fx(listing), '--lossless', '--field', 'T', '-o', out, '--json');
    assert.equal(pack.status, 0, pack.stderr);
    for (const value of ['1.5', '3.25']) {
      const whole = cli('iso', fx('box.vtu'), '--field', 'T', '--value', value, '--json').json;
      const packed = cli('iso', out, '--field', 'T', '--value', value, '--json').json;
      // petsc.vtu holds the box as hexahedra, split by the joined mesh's numbering: other tets,
      // but T is linear, so the same plane.
      if (listing !== 'petsc.vtu') {
        for (const k of ['triangles', 'vertices']) assert.equal(packed[k], whole[k], `${listing} ${value} ${k}`);
      }
      assert.ok(packed.triangles > 0);
      assert.ok(Math.abs(packed.area - whole.area) <= 1e-6 * whole.area, `${listing}: ${packed.area} vs ${whole.area}`);
    }
  }

  // A listing whose piece climbs out of its folder: refused, named, exit 1.
  fs.cpSync(path.join(root, 'tests/fixtures/partitioned'), path.join(dir, 'copy'), { recursive: true });
  const listing = path.join(dir, 'copy', 'ghost.pvtu');
  fs.writeFileSync(listing, fs.readFileSync(listing, 'utf8').replace('ghost/ghost_1.vtu', '../../etc/passwd'));
  const bad = cli('info', listing, '--json');
  assert.equal(bad.status, 1);
  assert.match(bad.stderr, /ghost\.pvtu piece 1: '\.\.\/\.\.\/etc\/passwd' leaves the listing's folder/);
  assert.equal(bad.json.error.status, 'unsupported');
  fs.rmSync(dir, { recursive: true, force: true });
});

// The commands that read an input start the program again with glibc's huge pages on
// (core/cli/huge_pages.h): the pack must be the same byte for byte with them, without them
// (TETSTREAM_HUGE_PAGES=0) and with a user's own GLIBC_TUNABLES kept (a small input also gets
// heap settings of its own, which must not override the user's), and the restart must happen
// once, not again and again (a loop would hit the timeout).
test('huge pages on, off or with the user\'s own glibc tunables: the same pack', () => {
  const dir = tempDir('huge-pages');
  const vtu = path.join(dir, 'h.vtu');
  assert.equal(cli('gen', 'harmonic', '--n', '10', '-o', vtu).status, 0);
  const manifests = [];
  for (const [name, env] of [['default', {}], ['off', { TETSTREAM_HUGE_PAGES: '0' }],
    ['own tunables', { GLIBC_TUNABLES: 'glibc.malloc.check=0' }], ['own heap tunables', { GLIBC_TUNABLES: 'glibc.malloc.top_pad=0' }]]) {
    const out = path.join(dir, name.replace(/ /g, '-'));
    const r = cliWithEnv({ ...process.env, ...env }, 'pack', vtu, '-o', out, '--json');
    assert.equal(r.status, 0, `${name}: ${r.stderr}`);
    assert.equal(r.json.tets, 9 ** 3 * 6, name);
    manifests.push(fs.readFileSync(path.join(out, 'manifest.json'), 'utf8'));
  }
  assert.equal(manifests[1], manifests[0], 'without huge pages');
  assert.equal(manifests[2], manifests[0], 'with the user\'s tunables');
  assert.equal(manifests[3], manifests[0], 'with the user\'s own heap settings');
});

// The CLI links the HPC container libraries dynamically (cmake/hpc_libs.cmake); it still needs
// nothing from the environment to run.
test('the CLI runs with nothing from the environment (no PATH, no library path)', () => {
  const dir = tempDir('bare-env');
  const vtu = path.join(dir, 'h.vtu');
  const gen = cliWithEnv({}, 'gen', 'harmonic', '--n', '6', '-o', vtu, '--json');
  assert.equal(gen.status, 0, gen.stderr);
  const pack = cliWithEnv({}, 'pack', vtu, '-o', path.join(dir, 'p'), '--json');
  assert.equal(pack.status, 0, pack.stderr);
  assert.equal(pack.json.tets, 5 ** 3 * 6);
});
