// Opens `fiveaxis view` pages in headless Chromium and prints, for each,
// the file size and the time from navigation to the viewer's ready flag
// (and to the path and machine drawn, before the program text is read),
// how long a seek (slider move) takes, a frame while orbiting (a mouse
// drag: the coarse path) and a frame of the whole path at rest.
//
//   node test/measure.mjs PAGE.html...

import { statSync } from 'node:fs';
import { resolve } from 'node:path';
import { launch, open } from './browser.mjs';

const browser = await launch();
for (const arg of process.argv.slice(2)) {
  const file = resolve(arg);
  const started = Date.now();
  const { page, errors, openMs } = await open(browser, file, { timeout: 600000 });
  const wall = Date.now() - started;
  const timing = await page.evaluate(async () => {
    const v = window.__viewer;
    const t0 = performance.now();
    for (let k = 1; k <= 20; k++) v.seek((v.stats.duration * k) / 21);
    const seekMs = (performance.now() - t0) / 20;
    // Frames drawn while orbiting: render on demand, measured over 20 frames.
    const f0 = v.renderedFrames();
    const t1 = performance.now();
    for (let k = 0; k < 20; k++) {
      v.view(k % 2 ? 'iso' : '+x');
      await new Promise(requestAnimationFrame);
    }
    const frameMs = (performance.now() - t1) / Math.max(1, v.renderedFrames() - f0);
    // One frame of the whole path and of the coarse one, drawn at once.
    const restMs = v.timeFrame(true);
    const drawn = v.drawn ? v.drawn() : { drawn: null };
    const coarseMs = v.timeFrame(false);
    const timings = Object.fromEntries(Object.entries(v.timings || {}).map(([k, x]) => [k, Math.round(x)]));
    return { interactiveMs: v.interactiveMs, seekMs, frameMs, restMs, coarseMs, coarse: v.coarse(), drawn, stats: v.stats, timings };
  });
  // Let the whole path drawn at rest after the view changes above pass
  // first (it would fall inside the drag).
  await page.waitForTimeout(400);
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  // Orbiting: a left drag across the 3-D view, frames as the browser draws them.
  const box = await page.locator('#fa-3d canvas').boundingBox();
  const x = box.x + box.width / 2;
  const y = box.y + box.height / 2;
  const before = await page.evaluate(() => window.__viewer.renderedFrames());
  const t0 = Date.now();
  await page.mouse.move(x, y);
  await page.mouse.down();
  for (let k = 1; k <= 20; k++) {
    await page.mouse.move(x + 8 * k, y + 3 * k);
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  }
  const orbitFrames = (await page.evaluate(() => window.__viewer.renderedFrames())) - before;
  const orbitMs = (Date.now() - t0) / Math.max(1, orbitFrames);
  await page.mouse.up();
  const mb = statSync(file).size / 1e6;
  console.log(JSON.stringify({ file: arg, megabytes: +mb.toFixed(1), openMs: Math.round(openMs), interactiveMs: Math.round(timing.interactiveMs || openMs), wallMs: wall, seekMs: +timing.seekMs.toFixed(2), frameMs: +timing.frameMs.toFixed(1), orbitMs: +orbitMs.toFixed(1), orbitFrames, restMs: Math.round(timing.restMs), restVertices: timing.drawn.drawn, coarseMs: Math.round(timing.coarseMs), coarseVertices: timing.coarse, segments: timing.stats.segments, vertices: timing.stats.vertices, timings: timing.timings, errors }));
  await page.close();
}
await browser.close();
