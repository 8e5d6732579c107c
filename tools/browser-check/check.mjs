#!/usr/bin/env node
// Renders the validation report in headless Chromium and fails on what a reader would hit:
// a missing image, a broken link, a console error, or a page that scrolls sideways at 1400 px.
//
//   node tools/browser-check/check.mjs <reports-dir> [--screenshots <dir>] [--all] [--page <rel path>]...
//
// Checks reports/index.html, the first case page it links (a <dir>/index.html whose directory
// holds results.json), every --page, and with --all every page the index links. Full-page screenshots go to <dir> (default
// <reports-dir>/screenshots/), also when a check fails. Exit 0 clean, 1 problems, 2 usage.
// Chromium is Debian's /usr/bin/chromium unless the env CHROMIUM names another binary.
import { chromium } from 'playwright-core';
import { existsSync, mkdirSync, readFileSync, statSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const VIEWPORT = { width: 1400, height: 900 };

function usage(msg) {
  console.error(`${msg}\nusage: node check.mjs <reports-dir> [--screenshots <dir>] [--all] [--page <rel path>]...`);
  process.exit(2);
}

// --- arguments -------------------------------------------------------------------------
let reportsDir;
let shotsDir;
const extraPages = [];
let all = false;
const args = process.argv.slice(2);
for (let i = 0; i < args.length; i++) {
  const a = args[i];
  if (a === '--screenshots' || a === '--page') {
    if (i + 1 >= args.length) usage(`${a} needs a value`);
    if (a === '--screenshots') shotsDir = args[++i];
    else extraPages.push(args[++i]);
  } else if (a === '--all') all = true;
  else if (a.startsWith('-')) usage(`unknown option ${a}`);
  else if (reportsDir === undefined) reportsDir = a;
  else usage(`unexpected argument ${a}`);
}
if (!reportsDir) usage('missing <reports-dir>');
reportsDir = path.resolve(reportsDir);
shotsDir = path.resolve(shotsDir ?? path.join(reportsDir, 'screenshots'));
const indexFile = path.join(reportsDir, 'index.html');
if (!existsSync(indexFile)) usage(`no ${indexFile}`);

// --- which pages -----------------------------------------------------------------------
// The first case page linked from the index: the figures and wide tables live there.
const pages = ['index.html'];
const indexHtml = readFileSync(indexFile, 'utf8');
for (const [, href] of indexHtml.matchAll(/<a\s[^>]*href="([^"#?]+\/index\.html)"/g)) {
  if (existsSync(path.join(reportsDir, path.dirname(href), 'results.json'))) {
    pages.push(href);
    break;
  }
}
// An index that links no case page has lost its cases: that is a failure, not a warning.
const indexProblems = [];
if (pages.length < 2) indexProblems.push('index.html: links no case page (<case>/index.html with results.json)');
// What the index must show (issue #39): the scheme-by-case matrix and the overview figure.
for (const [what, re] of [
  ['the scheme-by-case matrix (<table class="matrix">)', /<table class="matrix">/],
  ['the overview figure (<img src="overview.svg">)', /<img src="overview\.svg"/],
]) {
  if (!re.test(indexHtml)) indexProblems.push(`index.html: lacks ${what}`);
}
for (const p of extraPages) if (!pages.includes(p)) pages.push(p);
// --all: every page the index links (the cases, the stability and work-precision pages).
if (all) {
  for (const [, href] of indexHtml.matchAll(/<a\s[^>]*href="([^"#?:]+\.html)"/g)) {
    if (!pages.includes(href) && existsSync(path.join(reportsDir, href))) pages.push(href);
  }
}

// A name for the screenshot: index.png for the index, <case>.png for <case>/index.html.
const shotName = (rel) =>
  rel === 'index.html' ? 'index.png' : `${rel.replace(/\/index\.html$/, '').replace(/[/\\]/g, '_')}.png`;

// Whether a link's target exists on disk; a directory counts only with an index.html.
function linkTargetExists(file) {
  if (!existsSync(file)) return false;
  return !statSync(file).isDirectory() || existsSync(path.join(file, 'index.html'));
}

// --- the checks ------------------------------------------------------------------------
async function checkPage(browser, rel) {
  const problems = [];
  const report = (what) => problems.push(`${rel}: ${what}`);
  const url = pathToFileURL(path.join(reportsDir, rel)).href;
  const shown = (u) => (u.startsWith('file:') ? path.relative(reportsDir, fileURLToPath(u)) : u);
  const page = await browser.newPage({ viewport: VIEWPORT });
  // Console errors and uncaught exceptions: a self-contained page should have neither.
  page.on('console', (m) => {
    const from = m.location().url;
    if (m.type() !== 'error') return;
    report(`console error: ${m.text()}${from && from !== url ? ` (${shown(from)})` : ''}`);
  });
  page.on('pageerror', (e) => report(`page error: ${e.message}`));
  // Any resource (figure, stylesheet) the page asked for and did not get.
  page.on('requestfailed', (r) => report(`failed request: ${shown(r.url())} (${r.failure()?.errorText})`));
  let stats = '';
  try {
    await page.goto(url, { waitUntil: 'load' });

    // Images that loaded nothing (a missing or unreadable SVG shows as naturalWidth 0).
    const imgs = await page.$$eval('img', (els) =>
      els.map((e) => ({ src: e.getAttribute('src'), w: e.naturalWidth })),
    );
    for (const img of imgs) if (img.w === 0) report(`broken image: ${img.src}`);

    // Relative links must name a file that exists (the figure links, ../index.html, cases).
    const hrefs = await page.$$eval('a[href]', (els) => els.map((e) => [e.getAttribute('href'), e.href]));
    let links = 0;
    for (const [raw, abs] of hrefs) {
      if (/^(https?|mailto):/i.test(raw) || raw.startsWith('#')) continue;
      const target = new URL(abs);
      if (target.protocol !== 'file:') continue;
      links++;
      target.hash = '';
      target.search = '';
      if (!linkTargetExists(fileURLToPath(target))) report(`broken link: ${raw}`);
    }

    // No sideways scroll at 1400 px: name the widest element that sticks out on the right.
    const o = await page.evaluate(() => {
      const inner = window.innerWidth;
      const scroll = document.documentElement.scrollWidth;
      let worst = null;
      if (scroll > inner) {
        for (const el of document.body.querySelectorAll('*')) {
          const r = el.getBoundingClientRect();
          if (r.right > inner + 0.5 && (!worst || r.width > worst.width)) {
            const text = (el.innerText || el.textContent || '').trim().replace(/\s+/g, ' ').slice(0, 60);
            worst = { tag: el.tagName.toLowerCase(), width: Math.round(r.width), text };
          }
        }
      }
      return { inner, scroll, worst };
    });
    if (o.scroll > o.inner) {
      const w = o.worst ? `; widest: <${o.worst.tag}> ${o.worst.width} px "${o.worst.text}"` : '';
      report(`scrolls sideways: ${o.scroll} px wide at a ${o.inner} px viewport${w}`);
    }
    stats = `${imgs.length} images, ${links} links checked, width ${o.scroll}/${o.inner} px`;
  } catch (e) {
    report(`could not check: ${e.message.split('\n')[0]}`);
  } finally {
    // The screenshot is kept whatever the outcome: it is what the CI artifact shows.
    try {
      await page.screenshot({ path: path.join(shotsDir, shotName(rel)), fullPage: true });
    } catch (e) {
      report(`screenshot failed: ${e.message.split('\n')[0]}`);
    }
    await page.close();
  }
  return { problems, stats };
}

// --- run -------------------------------------------------------------------------------
mkdirSync(shotsDir, { recursive: true });
const executablePath = process.env.CHROMIUM || '/usr/bin/chromium';
const browser = await chromium.launch({ executablePath }).catch((e) => {
  console.error(`cannot start ${executablePath}: ${e.message.split('\n')[0]}`);
  process.exit(2);
});
const allProblems = [...indexProblems];
try {
  for (const rel of pages) {
    const { problems, stats } = await checkPage(browser, rel);
    console.log(`${problems.length ? 'FAIL' : 'ok  '} ${rel}: ${stats || 'not loaded'}`);
    allProblems.push(...problems);
  }
} finally {
  await browser.close();
}
const shotsShown = path.relative(process.cwd(), shotsDir);
console.log(`screenshots in ${shotsShown.startsWith('..') ? shotsDir : shotsShown || '.'}/`);
if (allProblems.length) {
  console.log(`\n${allProblems.length} problem(s):`);
  for (const p of allProblems) console.log(`  ${p}`);
  process.exit(1);
}
