// Opens `fiveaxis view` pages in Debian's Chromium (headless, WebGL on
// SwiftShader) through playwright-core, which downloads no browser.

import { chromium } from 'playwright-core';

/** Chromium: $CHROMIUM, else Debian's /usr/bin/chromium. */
export const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';

export async function launch() {
  return chromium.launch({
    executablePath: CHROMIUM,
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox'],
  });
}

/**
 * Opens a page file and waits for the viewer's ready flag. Returns the
 * page, the console errors and page errors seen, and the time from
 * navigation to ready (ms, as the page measured it).
 */
export async function open(browser, file, { width = 1400, height = 860, timeout = 120000 } = {}) {
  const page = await browser.newPage({ viewport: { width, height } });
  const errors = [];
  page.on('console', (m) => {
    if (m.type() === 'error') errors.push(m.text());
  });
  page.on('pageerror', (e) => errors.push(String(e)));
  // Nothing but the file itself may load.
  const requests = [];
  page.on('request', (r) => requests.push(r.url()));
  await page.goto(`file://${file}`, { timeout });
  await page.waitForFunction(() => window.__viewer && (window.__viewer.ready || window.__viewer.error), null, { timeout });
  const openMs = await page.evaluate(() => window.__viewer.openMs);
  return { page, errors, requests, openMs };
}
