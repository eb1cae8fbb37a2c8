#!/usr/bin/env node
// Headless-browser test of the live view (host/view/VIEW_PROTOCOL.md) against a running
// `tissue-host run SCENARIO.toml --view`. Uses playwright-core with the system Chromium (it never
// downloads a browser).
//
//   node tests/host/browser/view_test.mjs --url http://127.0.0.1:8080/ [--viewers N] [--drag]
//        [--seconds S] [--screenshot out.png] [--json out.json] [--bad-messages]
//        [--viewport 960x540] [--chromium /usr/bin/chromium] [--timeout SECONDS]
//
// Opens N pages, waits until each is connected and has a frame, optionally drags a scalpel
// through the body on page 1 (--drag), measures frames received and rendered per second over
// --seconds, takes a screenshot of page 1, optionally sends malformed / oversized / flooding
// messages from an extra socket inside page 1 (--bad-messages), and writes a JSON report.
// Exit status: 0 when the run completed; 1 on a failure (no connection, no WebGL, a script error
// in a page, a page that lost its connection); 2 on bad arguments.
import { chromium } from 'playwright-core';
import { writeFileSync } from 'node:fs';

// ---------------------------------------------------------------------------------------------
// Arguments
function parseArgs(argv) {
  const o = {
    url: null, screenshot: null, viewers: 1, drag: false, seconds: 5, json: null, badMessages: false,
    chromium: process.env.CHROMIUM_PATH || '/usr/bin/chromium', timeout: 30,
    // Software WebGL is slow: a modest default page size keeps the measured fps meaningful.
    viewport: { width: 960, height: 540 },
  };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    const value = () => {
      if (i + 1 >= argv.length) usage(`${a} needs a value`);
      return argv[++i];
    };
    switch (a) {
      case '--url': o.url = value(); break;
      case '--screenshot': o.screenshot = value(); break;
      case '--viewers': o.viewers = Number(value()); break;
      case '--drag': o.drag = true; break;
      case '--seconds': o.seconds = Number(value()); break;
      case '--json': o.json = value(); break;
      case '--bad-messages': o.badMessages = true; break;
      case '--chromium': o.chromium = value(); break;
      case '--timeout': o.timeout = Number(value()); break;
      case '--viewport': {
        const m = /^(\d+)x(\d+)$/.exec(value());
        if (!m) usage('--viewport must look like 960x540');
        o.viewport = { width: Number(m[1]), height: Number(m[2]) };
        break;
      }
      case '-h': case '--help': usage(null); break;
      default: usage(`unknown argument ${a}`);
    }
  }
  if (!o.url) usage('--url is required');
  if (!Number.isInteger(o.viewers) || o.viewers < 1) usage('--viewers must be a positive integer');
  if (!(o.seconds > 0)) usage('--seconds must be positive');
  if (!(o.timeout > 0)) usage('--timeout must be positive');
  return o;
}

function usage(error) {
  if (error) console.error(`view_test: ${error}`);
  console.error('usage: view_test.mjs --url URL [--viewers N] [--drag] [--seconds S] [--screenshot PNG]\n' +
                '                     [--json OUT] [--bad-messages] [--viewport WxH] [--chromium PATH] [--timeout S]');
  process.exit(error ? 2 : 0);
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Counters of the page, read together.
const snapshot = (page) => page.evaluate(() => {
  const t = window.tissueView;
  return { t: performance.now(), connected: t.connected, framesReceived: t.framesReceived,
           framesRendered: t.framesRendered, posesSent: t.posesSent, statsReceived: t.statsReceived,
           fps: t.fps, applyMs: t.applyMsTotal, renderMs: t.renderMsTotal };
});

// ---------------------------------------------------------------------------------------------
// Drag a scalpel through the middle of the body on `page`.
async function scriptedCut(page) {
  const hello = await page.evaluate(() => window.tissueView.hello);
  if (!hello.controls) throw new Error('--drag: the session does not give the page the controls (hello.controls is false)');
  const [lx, ly, lz] = hello.bounds.lower;
  const [ux, uy, uz] = hello.bounds.upper;
  const cx = (lx + ux) / 2;
  const margin = Math.max(0.1 * (uy - ly), 0.003);
  const y0 = ly - margin, y1 = uy + margin;
  const z0 = lz + 0.3 * (uz - lz);              // tip inside the body, the blade reaching up through it
  const above = uz + 0.02;
  const statsBefore = await page.evaluate(() => window.tissueView.lastStats);

  // Place the tool beside the body with no tool active, lower it, then take the scalpel, so that
  // no move but the drag sweeps the blade through the tissue.
  await page.evaluate((p) => window.tissueView.setTool(p, 'none'), [cx, y0, above]);
  await sleep(150);
  await page.evaluate((p) => window.tissueView.setTool(p, 'none'), [cx, y0, z0]);
  await sleep(150);
  await page.keyboard.press('2');
  await sleep(300);
  const modeAfterKey = await page.evaluate(() => window.tissueView.getTool().mode);
  if (modeAfterKey !== 'scalpel') throw new Error(`--drag: key 2 gave mode ${modeAfterKey}, not scalpel`);

  // Left-drag along +y at the tip's depth: 40 moves over about 2 s.
  const start = await page.evaluate((p) => window.tissueView.screenOf(p), [cx, y0, z0]);
  const end = await page.evaluate((p) => window.tissueView.screenOf(p), [cx, y1, z0]);
  const steps = 40;
  await page.mouse.move(start.x, start.y);
  await page.mouse.down({ button: 'left' });
  for (let i = 1; i <= steps; i++) {
    const f = i / steps;
    await page.mouse.move(start.x + f * (end.x - start.x), start.y + f * (end.y - start.y));
    await sleep(50);
  }
  await page.mouse.up({ button: 'left' });
  const toolAfter = await page.evaluate(() => window.tissueView.getTool());

  // The scalpel stays beside the body (kept alive by the page) until after the screenshot.
  // Let the host report the cut.
  const n = await page.evaluate(() => window.tissueView.statsReceived);
  await page.waitForFunction((k) => window.tissueView.statsReceived > k + 1, n, { timeout: 5000 }).catch(() => {});
  const statsAfter = await page.evaluate(() => window.tissueView.lastStats);
  const topology = await page.evaluate(() => window.tissueView.lastFrame &&
    { revision: window.tissueView.lastFrame.topologyRevision, triangles: window.tissueView.lastFrame.triangleCount,
      mesh_triangles: window.tissueView.lastFrame.meshTriangleCount });
  return {
    from_m: [cx, y0, z0], to_m: [cx, y1, z0], screen_from: start, screen_to: end,
    tool_after_drag: toolAfter,
    cut_tets_before: statsBefore ? statsBefore.cut_tets : null,
    cut_tets_after: statsAfter ? statsAfter.cut_tets : null,
    topology_after: topology,
  };
}

// ---------------------------------------------------------------------------------------------
// From inside `page`, open an extra socket to the same /ws and send bad messages.
async function sendBadMessages(page) {
  const before = await page.evaluate(() => ({ stats: window.tissueView.lastStats, n: window.tissueView.statsReceived,
                                              frames: window.tissueView.framesReceived }));
  const sent = await page.evaluate(async () => {
    const scheme = location.protocol === 'https:' ? 'wss' : 'ws';
    const m = /[?&]token=([^&#]*)/.exec(location.search);
    const url = `${scheme}://${location.host}/ws` + (m ? `?token=${m[1]}` : '');
    const tool = window.tissueView.getTool();
    // Harmless poses (mode none at the current tool position), should the host act on them.
    const pose = (seq) => JSON.stringify({ type: 'pose', seq, position_m: tool.position_m,
                                           orientation_wxyz: [1, 0, 0, 0], mode: 'none' });
    const groups = [
      ['truncated_json', [pose(1).slice(0, 25)]],
      ['oversized_100kB', ['{"type":"pose","pad":"' + 'x'.repeat(100000) + '"}']],
      ['binary', [new Uint8Array([0x54, 0x56, 0x46, 0x31, 1, 2, 3, 4])]],
      ['wrong_type', ['{"type":"nonsense"}']],
      ['nan_pose', [JSON.stringify({ type: 'pose', seq: 2, position_m: ['a', 'b', 'c'], orientation_wxyz: [1, 0, 0, 0], mode: 'none' }),
                    '{"type":"pose","seq":3,"position_m":[1e999,0,0],"orientation_wxyz":[1,0,0,0],"mode":"none"}']],
      ['seq_not_increasing', [pose(10), pose(10), pose(9)]],
      ['flood_5000', Array.from({ length: 5000 }, (_, i) => pose(100 + i))],
    ];
    const open = () => new Promise((resolve, reject) => {
      const ws = new WebSocket(url);
      ws.binaryType = 'arraybuffer';
      ws.closeInfo = null;
      ws.onopen = () => resolve(ws);
      ws.onerror = () => {};
      ws.onclose = (ev) => { ws.closeInfo = { code: ev.code, reason: ev.reason }; reject(new Error('closed before open')); };
    });
    const drained = async (ws) => {
      for (let i = 0; i < 200 && ws.readyState === WebSocket.OPEN && ws.bufferedAmount > 0; i++) {
        await new Promise((r) => setTimeout(r, 10));
      }
    };
    const report = [];
    let ws = null;
    for (const [name, messages] of groups) {
      if (!ws || ws.readyState !== WebSocket.OPEN) ws = await open();
      const t0 = performance.now();
      for (const msg of messages) {
        if (ws.readyState !== WebSocket.OPEN) break;
        ws.send(msg);
      }
      const sendMs = performance.now() - t0;
      await drained(ws);
      await new Promise((r) => setTimeout(r, 100));   // let the host react (it may close)
      report.push({ name, messages: messages.length, send_ms: Math.round(sendMs),
                    closed_by_host: ws.readyState !== WebSocket.OPEN, close: ws.closeInfo });
    }
    if (ws.readyState === WebSocket.OPEN) ws.close();
    return report;
  });

  // Wait 1 s, then for the next stats message.
  await sleep(1000);
  const n = await page.evaluate(() => window.tissueView.statsReceived);
  await page.waitForFunction((k) => window.tissueView.statsReceived > k, n, { timeout: 5000 }).catch(() => {});
  const after = await page.evaluate(() => ({ stats: window.tissueView.lastStats, connected: window.tissueView.connected,
                                             frames: window.tissueView.framesReceived }));
  const keys = ['received', 'accepted', 'malformed', 'oversized', 'flood', 'out_of_order'];
  const counters = {};
  for (const k of keys) {
    const a = after.stats && after.stats.messages ? after.stats.messages[k] : undefined;
    const b = before.stats && before.stats.messages ? before.stats.messages[k] : 0;
    counters[k] = { total: a ?? null, delta: a === undefined ? null : a - (b ?? 0) };
  }
  return {
    groups: sent, counters,
    page_still_connected: after.connected,
    page_frames_during: after.frames - before.frames,
    stats_after: after.stats,
  };
}

// ---------------------------------------------------------------------------------------------
async function main() {
  const o = parseArgs(process.argv.slice(2));
  const browser = await chromium.launch({
    executablePath: o.chromium,
    headless: true,
    // SwiftShader (software WebGL) so that the test runs without a GPU.
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  const failures = [];
  const consoleErrors = [];
  const pages = [];
  // Filled as the run goes, written (with the failures) even when the run stops early.
  const result = { url: o.url, viewers: o.viewers, seconds: o.seconds };
  try {
    for (let i = 0; i < o.viewers; i++) {
      // One context (window) per viewer, as separate browsers would be.
      const context = await browser.newContext({ viewport: o.viewport });
      const page = await context.newPage();
      page.on('console', (msg) => { if (msg.type() === 'error') consoleErrors.push(`page ${i + 1}: ${msg.text()}`); });
      page.on('pageerror', (err) => failures.push(`page ${i + 1}: script error: ${err.message}`));
      await page.goto(o.url, { waitUntil: 'load', timeout: o.timeout * 1000 });
      pages.push(page);
    }
    for (const [i, page] of pages.entries()) {
      await page.waitForFunction(() => window.tissueView && window.tissueView.connected &&
                                        window.tissueView.framesReceived > 0, null, { timeout: o.timeout * 1000 })
        .catch(() => { throw new Error(`page ${i + 1}: not connected with a frame after ${o.timeout} s`); });
      const webgl = await page.evaluate(() => window.tissueView.webgl);
      if (!webgl) failures.push(`page ${i + 1}: no WebGL`);
    }
    const hello = await pages[0].evaluate(() => window.tissueView.hello);
    result.scenario = hello && hello.scenario;
    result.controls = hello && hello.controls;

    const drag = o.drag ? await scriptedCut(pages[0]) : null;
    result.drag = drag;

    // Measure frames received and rendered per second on every page over the same interval.
    const start = await Promise.all(pages.map(snapshot));
    await sleep(o.seconds * 1000);
    const end = await Promise.all(pages.map(snapshot));
    const rate = (k) => end.map((e, i) => +((e[k] - start[i][k]) / ((e.t - start[i].t) / 1000)).toFixed(2));
    const framesPerS = rate('framesReceived');
    const fps = rate('framesRendered');
    // Milliseconds per rendered frame spent applying the surface and in three.js' render call.
    const per = (k) => end.map((e, i) => +((e[k] - start[i][k]) / Math.max(1, e.framesRendered - start[i].framesRendered)).toFixed(2));
    const applyMs = per('applyMs'), renderMs = per('renderMs');
    end.forEach((e, i) => { if (!e.connected) failures.push(`page ${i + 1}: disconnected during the measurement`); });

    if (o.screenshot) await pages[0].screenshot({ path: o.screenshot });
    if (drag) await pages[0].keyboard.press('0');   // put the scalpel away

    const bad = o.badMessages ? await sendBadMessages(pages[0]) : null;
    if (bad && !bad.page_still_connected) failures.push('page 1 lost its connection after the bad messages');

    const final = await Promise.all(pages.map(snapshot));
    const lastStats = await pages[0].evaluate(() => window.tissueView.lastStats);
    Object.assign(result, {
      frames_per_s: framesPerS, fps, apply_ms_per_frame: applyMs, render_ms_per_frame: renderMs,
      poses_sent: final[0].posesSent,
      bad_messages: bad,
      last_stats: lastStats,
    });

    let line = `view_test: ${o.viewers} viewer(s), frames/s [${framesPerS.join(', ')}], fps [${fps.join(', ')}], ` +
      `poses sent ${result.poses_sent}`;
    if (drag) line += `, cut tets ${drag.cut_tets_before} -> ${drag.cut_tets_after}`;
    if (bad) {
      const c = bad.counters;
      line += `, bad messages: malformed +${c.malformed.delta} oversized +${c.oversized.delta} flood +${c.flood.delta}` +
        ` out_of_order +${c.out_of_order.delta}`;
    }
    console.log(line);
  } catch (err) {
    failures.push(err.message);
  } finally {
    await browser.close();
  }
  result.console_errors = consoleErrors;
  result.failures = failures;
  if (o.json) writeFileSync(o.json, JSON.stringify(result, null, 2) + '\n');
  for (const e of consoleErrors) console.error(`console error: ${e}`);
  for (const f of failures) console.error(`FAIL: ${f}`);
  process.exit(failures.length ? 1 : 0);
}

main();
