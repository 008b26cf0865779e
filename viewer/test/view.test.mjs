// `fiveaxis view` pages in a real browser (Debian's Chromium, headless,
// WebGL on SwiftShader), driven by playwright-core: for the example
// programs on each built-in machine type the page opens with no console
// error and loads nothing but itself; the statistics the viewer exposes
// match what `fiveaxis run` reports; moving the slider moves the machine
// bodies as forward kinematics says (compared with the kernel's rows);
// clicking the text or the path selects a line; a screenshot is saved.

import assert from 'node:assert/strict';
import { after, before, test } from 'node:test';
import { spawnSync } from 'node:child_process';
import { mkdirSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { launch, open } from './browser.mjs';
import { CASES, FIVEAXIS, OUT, ROOT, blockRows, checkReport, makePage, runRows } from './cases.mjs';

let browser;
before(async () => {
  browser = await launch();
});
after(async () => {
  await browser?.close();
});

/** Millimetres: joints are packed as 32-bit floats. */
const MM = 1e-3;

function near(a, b, tol, what) {
  assert.ok(Math.abs(a - b) <= tol, `${what}: ${a} vs ${b} (tolerance ${tol})`);
}

/** A rollover axis as `run` prints it. */
const mod360 = (x) => ((x % 360) + 360) % 360;
function angleNear(a, b, tol, what) {
  const d = Math.abs(mod360(a) - mod360(b));
  assert.ok(Math.min(d, 360 - d) <= tol, `${what}: ${a} vs ${b}`);
}

for (const c of CASES) {
  const name = `${c.program} on ${c.machine}`;
  test(`view: ${name}`, async () => {
    const { file, status, meta } = makePage(c);
    const plain = runRows(c);
    const segments = plain.rows.length;
    plain.rows = blockRows(plain.rows);
    assert.equal(meta.segments, segments, 'segments = rows of run without --step');
    const stepped = runRows(c, ['--step', '1', '--step-angle', '1']);
    assert.equal(status, c.alarm ? 1 : 0, 'exit status as run');
    assert.equal(plain.status, status);
    const { page, errors, requests, openMs } = await open(browser, file);
    try {
      assert.deepEqual(errors, [], 'no console error');
      assert.deepEqual(requests, [`file://${file}`], 'the page loads nothing but itself');
      assert.ok(openMs > 0);
      const stats = await page.evaluate(() => window.__viewer.stats);

      // Statistics against `fiveaxis run`.
      assert.equal(stats.segments, plain.rows.length, 'blocks = runs of rows of one line and motion');
      assert.equal(stats.rows, stepped.rows.length, 'rows sampled = rows of run --step 1');
      // Findings: those of `fiveaxis check` on the same program, in order.
      const report = checkReport(c);
      assert.equal(stats.findings, report.findings.length, 'findings = check findings');
      const shown = await page.evaluate(() => window.__viewer.findings());
      assert.deepEqual(
        shown.map((f) => [f.kind, f.line]),
        report.findings.map((f) => [f.kind, f.line]),
        'findings as check reports them',
      );
      assert.deepEqual(
        shown.map((f) => [f.severity, f.message, f.axis, f.value]),
        report.findings.map((f) => [f.severity, f.message, f.axis, f.value]),
        'severity, message, axis and value as check reports them',
      );
      if (plain.alarm) assert.equal(shown.at(-1).line, plain.alarm.line);
      if (stepped.rows.length) {
        for (const [k, axis] of ['tip_x', 'tip_y', 'tip_z'].entries()) {
          const values = stepped.rows.map((r) => r[axis]);
          near(stats.bbox.min[k], Math.min(...values), MM + meta.tolerance, `bbox min ${axis}`);
          near(stats.bbox.max[k], Math.max(...values), MM + meta.tolerance, `bbox max ${axis}`);
        }
      } else assert.equal(stats.bbox, null);
      // Duration: the time of `fiveaxis check` (its estimated time, block
      // by block), and the page says which time it shows.
      const ends = await page.evaluate(() => window.__viewer.blockEnds());
      assert.equal(ends.length, plain.rows.length, 'an end per block');
      for (let b = 1; b < ends.length; b++) assert.ok(ends[b] >= ends[b - 1], `block ${b + 1} ends before the one before (line ${plain.rows[b].line})`);
      near(stats.duration, ends.at(-1) ?? 0, 1e-9, 'duration = end of the last block');
      assert.equal(stats.duration, report.time.estimated, "duration = check's estimated time");
      assert.equal(meta.time.estimated, report.time.estimated);
      assert.equal(meta.time.programmed, report.time.programmed);
      const label = await page.locator('#fa-timekind').textContent();
      assert.equal(label, meta.time.label);
      assert.match(label, new RegExp(`^${meta.time.kind} machining time .*as fiveaxis check$`));

      // The slider moves the bodies; at each block end they stand where
      // the kernel's row says.
      if (plain.rows.length) {
        const slider = page.locator('#fa-slider');
        const moveSlider = (v) => slider.evaluate((el, v) => { el.value = String(v); el.dispatchEvent(new Event('input', { bubbles: true })); }, v);
        await moveSlider(0);
        const a = await page.evaluate(() => window.__viewer.probe());
        await moveSlider(500000);
        const b = await page.evaluate(() => window.__viewer.probe());
        near(b.t, stats.duration / 2, stats.duration * 1e-5, 'slider time');
        const moved = a.joints.some((x, i) => Math.abs(x - b.joints[i]) > 1e-6);
        const bodiesMoved = Object.keys(a.bodies.matrices).some((k) => a.bodies.matrices[k].some((x, i) => Math.abs(x - b.bodies.matrices[k][i]) > 1e-9));
        assert.equal(bodiesMoved, moved, 'bodies move when the axes do');
        const axisNames = [...meta.machine.linear.map((x) => x.name), ...meta.machine.rotary.map((x) => x.name)];
        const rollover = new Set(meta.machine.rotary.filter((r) => r.rollover).map((r) => r.name));
        const every = Math.max(1, Math.floor(plain.rows.length / 40));
        for (let k = 0; k < plain.rows.length; k += every) {
          const row = plain.rows[k];
          const p = await page.evaluate((k) => { window.__viewer.seekBlock(k); return window.__viewer.probe(); }, k);
          assert.equal(p.line, row.line, `block ${k}: line`);
          axisNames.forEach((n, i) => (rollover.has(n) ? angleNear : near)(p.joints[i], row[n], MM, `block ${k} (line ${row.line}): ${n}`));
          const tip = [row.tip_x, row.tip_y, row.tip_z];
          for (let j = 0; j < 3; j++) {
            near(p.bodiesTipPart[j], tip[j], MM, `block ${k} (line ${row.line}): tool tip of the bodies [${j}]`);
            near(p.fkDirPart[j], [row.tool_i, row.tool_j, row.tool_k][j], 1e-5, `block ${k}: tool direction [${j}]`);
          }
        }

        // The text selects a line: the machine goes to its first block.
        const line = plain.rows[Math.floor(plain.rows.length / 2)].line;
        await page.evaluate((line) => {
          const scroller = document.getElementById('fa-text');
          scroller.scrollTop = (line - 3) * 18;
          scroller.dispatchEvent(new Event('scroll'));
        }, line);
        await page.click(`#fa-text .ln[data-line="${line}"]`);
        const sel = await page.evaluate(() => ({ line: window.__viewer.selectedLine, p: window.__viewer.probe() }));
        assert.equal(sel.line, line, 'clicked text line selected');
        assert.equal(sel.p.line, line, 'the machine stands at the selected line');

        // The path selects a line: click on the end of a cutting block.
        await page.evaluate(() => window.__viewer.view('iso'));
        await page.waitForTimeout(50);
        const cut = plain.rows.findIndex((r, i) => i > 0 && r.motion !== 'rapid');
        if (cut >= 0) {
          const target = await page.evaluate((b) => {
            const v = window.__viewer;
            const i = v.vertexOfBlockEnd(b);
            const at = v.screenOfVertex(i);
            // Every line whose path passes within the pick distance of that point.
            return { at, lines: v.linesNear(at.x, at.y, 8) };
          }, cut);
          await page.mouse.click(target.at.x, target.at.y);
          const picked = await page.evaluate(() => window.__viewer.selectedLine);
          assert.ok(target.lines.includes(picked), `picked line ${picked} is one of the lines there: ${target.lines}`);
          assert.ok(target.lines.includes(plain.rows[cut].line));
        }
        await page.evaluate(() => window.__viewer.view('iso'));
        await moveSlider(600000);
      }
      // The path to the pixel: at the fitted view no more than the whole
      // path is drawn; close up, every vertex.
      const lod = await page.evaluate(() => {
        const v = window.__viewer;
        v.view('iso');
        v.setDetail(true);
        v.renderNow();
        const fit = v.drawn();
        v.zoomBy(1 / 4096);
        v.renderNow();
        const near = v.drawn();
        v.view('iso');
        return { fit, near };
      });
      assert.ok(lod.fit.drawn <= lod.fit.total, `drawn ${lod.fit.drawn} of ${lod.fit.total}`);
      assert.equal(lod.near.drawn, lod.near.total, 'close up, every vertex is drawn');
      await page.waitForTimeout(100);
      await page.screenshot({ path: join(OUT, `${c.program.replace(/\.nc$/, '')}-${c.machine}.png`) });
      assert.deepEqual(errors, [], 'no console error after use');
    } finally {
      await page.close();
    }
  });
}

// The stock a HEIDENHAIN program declares (BLK FORM): drawn where the
// workpiece is, carried by the table axes as the path, and a layer the
// Stock button shows and hides.
test('view: the BLK FORM stock of a Klartext program on heidenhain-dmu-ac', async () => {
  mkdirSync(OUT, { recursive: true });
  const program = join(OUT, 'blk-form.h');
  writeFileSync(
    program,
    ['0 BEGIN PGM BLK MM', '1 BLK FORM 0.1 Z X-50 Y-30 Z-20', '2 BLK FORM 0.2 X+50 Y+30 Z+0', '3 TOOL CALL 1 Z S3000', '4 L Z+50 R0 FMAX M3',
      '5 L X-40 Y-20 R0 FMAX', '6 L Z-2 R0 F200', '7 L X+40 F500', '8 L Z+50 R0 FMAX', '9 L C+90 FMAX', '10 END PGM BLK MM', ''].join('\n'),
  );
  const file = join(OUT, 'blk-form.html');
  const r = spawnSync(FIVEAXIS, ['view', program, '--machine', 'heidenhain-dmu-ac', '-o', file], { encoding: 'utf8' });
  assert.equal(r.status, 0, r.stderr);
  const { page, errors } = await open(browser, file);
  try {
    assert.deepEqual(errors, [], 'no console error');
    const stock = await page.evaluate(() => window.__viewer.stock());
    assert.equal(stock.declared, true);
    assert.equal(stock.visible, true, 'on at first');
    assert.deepEqual(stock.corners[0], [-50, -30, -20]);
    assert.deepEqual(stock.corners[7], [50, 30, 0]);
    // On the table's innermost axis, as the path: where C turns, it turns.
    assert.equal(stock.carrier, 'table-C');
    const last = await page.evaluate(() => {
      const v = window.__viewer;
      v.seekBlock(v.blockEnds().length - 1);
      return { stock: v.stock(), probe: v.probe() };
    });
    assert.deepEqual(last.stock.world, last.probe.bodies.matrices['table-C'], 'the stock moves with the table');
    near(Math.abs(last.stock.world[1]), 1, 1e-9, 'turned 90° about Z');
    // The layer button.
    const button = page.locator('#fa-stock');
    assert.equal(await button.isVisible(), true);
    await button.click();
    assert.equal((await page.evaluate(() => window.__viewer.stock())).visible, false, 'hidden');
    assert.equal(await button.getAttribute('aria-pressed'), 'false');
    await button.click();
    assert.equal((await page.evaluate(() => window.__viewer.stock())).visible, true, 'shown again');
    await page.screenshot({ path: join(OUT, 'blk-form.png') });
  } finally {
    await page.close();
  }
});

// The work on the table (`view --stock --fixture`): the machine file's
// bodies instead of the generic ones, the tool with its holder, the
// fixtures and the stock left, and the collision `check` finds.
test('view: bodies, tool, fixtures and the stock left of examples/pocket.nc', async () => {
  mkdirSync(OUT, { recursive: true });
  const file = join(OUT, 'pocket-work.html');
  const r = spawnSync(
    FIVEAXIS,
    ['view', join(ROOT, 'examples/pocket.nc'), '--offsets', join(ROOT, 'examples/offsets.toml'), '--stock', 'box:-40,-30,-25,40,30,0',
      '--fixture', 'box:-40,30,-25,40,42,12', '--fixture', 'box:-40,-42,-25,40,-30,12', '-o', file],
    { encoding: 'utf8' },
  );
  assert.equal(r.status, 0, r.stderr);
  const { page, errors } = await open(browser, file);
  try {
    assert.deepEqual(errors, [], 'no console error');
    const work = await page.evaluate(() => {
      const v = window.__viewer;
      v.seekBlock(0);
      return v.work();
    });
    // trunnion-ac's bodies, and nothing generic.
    for (const name of ['body-bed', 'body-cradle', 'body-table', 'body-head']) assert.ok(work[name], `${name} drawn`);
    // G54 is 50 mm up the table: the jaws from z 25 to 62, the stock
    // left from its bottom (25) to its top (50), the pocket cut into it.
    near(work['fixture-box 1'].min[2], 25, 1e-6, 'jaw bottom');
    near(work['fixture-box 1'].max[2], 62, 1e-6, 'jaw top');
    near(work['stock-left'].min[2], 25, 1e-4, 'stock bottom');
    near(work['stock-left'].max[2], 50, 1e-4, 'stock top');
    // The end mill: 10 mm across, 25 mm of flute, from its tip up.
    near(work.cutter.max[0] - work.cutter.min[0], 10, 1e-6, 'cutter diameter');
    near(work.cutter.max[2] - work.cutter.min[2], 25, 1e-6, 'flute length');
    // The stock as the slider moves: whole at the start, the first level
    // (3 mm) cut by line 15, both (6 mm) at the end; the pocket's middle
    // is the grid's.
    const centre = (s) => s.tops[Math.floor(s.ny / 2) * s.nx + Math.floor(s.nx / 2)];
    const atStart = await page.evaluate(() => window.__viewer.stockTops());
    near(centre(atStart), 50, 1e-4, 'uncut at the start');
    assert.ok(atStart.snapshots > 5, `snapshots: ${atStart.snapshots}`);
    await page.evaluate(() => window.__viewer.selectLine(15));
    near(centre(await page.evaluate(() => window.__viewer.stockTops())), 47, 1e-4, 'first level cut by line 15');
    await page.evaluate(() => window.__viewer.seek(1e9));
    const atEnd = await page.evaluate(() => window.__viewer.stockTops());
    near(centre(atEnd), 44, 1e-4, 'both levels at the end');
    await page.evaluate(() => window.__viewer.seekBlock(0));
    near(centre(await page.evaluate(() => window.__viewer.stockTops())), 50, 1e-4, 'whole again, back at the start');
    const findings = await page.evaluate(() => window.__viewer.findings());
    assert.deepEqual(findings.map((f) => [f.line, f.kind]), [[28, 'collision']]);
    // The collision's marker at the contact point (the holder against a
    // jaw, above the stock's top), not on the path.
    const marker = await page.evaluate(() => window.__viewer.markers()[0]);
    assert.ok(marker[2] > 50, `marker z ${marker[2]}`);
    await page.evaluate(() => window.__viewer.selectLine(28));
    await page.screenshot({ path: join(OUT, 'pocket-work.png') });
  } finally {
    await page.close();
  }
});
