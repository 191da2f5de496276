// What a request path may look like, and where it may lead. serve-static already refuses `..`
// after decoding and NUL bytes; we check the raw request target first and more strictly (a
// dataset and the viewer only ever need plain names), then make sure the file's real path, with
// every symlink resolved, is inside the served folder (serve-static follows symlinks anywhere).
import fs from 'node:fs';
import path from 'node:path';

// Returns { rawPath, query, decoded } for a usable request target, else { status, reason }.
export function checkRequestPath(url) {
  const bad = (reason, status = 400) => ({ status, reason });
  if (typeof url !== 'string' || !url.startsWith('/')) return bad('the request target must be a path starting with /');
  const q = url.indexOf('?');
  const rawPath = q < 0 ? url : url.slice(0, q);
  const query = q < 0 ? '' : url.slice(q);
  if (rawPath.includes('\\') || /%5c/i.test(rawPath)) return bad('backslash in path');
  if (/%00/.test(rawPath)) return bad('NUL byte in path');
  if (/%2f/i.test(rawPath)) return bad('encoded slash in path');
  if (rawPath.includes('#')) return bad('"#" in path');
  let decoded;
  try {
    decoded = decodeURIComponent(rawPath);
  } catch {
    return bad('malformed percent-encoding');
  }
  // %252e%252e decodes to %2e%2e: nothing we serve has an encoded name, so a second layer of
  // encoding can only be an attempt to fool a later decoder.
  if (/%[0-9a-f]{2}/i.test(decoded)) return bad('double percent-encoding');
  // Control characters (NUL, CR, LF...) and backslashes that arrived encoded in other ways.
  if (/[\x00-\x1f\x7f\\]/.test(decoded)) return bad('control character in path');
  if (decoded.includes('//')) return bad('empty path segment (//)');
  const segments = decoded.split('/').slice(1);
  if (segments.some((s) => s === '.' || s === '..')) return bad('"." or ".." segment');
  // Dotfiles (.git, .env, .htpasswd): not found, whether or not they exist.
  if (segments.some((s) => s.startsWith('.'))) return bad('hidden file', 404);
  return { rawPath, query, decoded };
}

export function isInside(root, file) {
  const base = root.endsWith(path.sep) ? root : root + path.sep;
  return file === root || file.startsWith(base);
}

// Resolves a checked, decoded path (relative to the mount, starting with /) inside rootReal
// (a realpath). Returns { file, stat } for a regular file, with the index.html of a directory
// asked for with a trailing slash; null when there is nothing to serve or it lies outside.
export async function resolveInRoot(rootReal, rel) {
  const target = path.join(rootReal, rel);
  const found = await realStat(rootReal, target);
  if (!found) return null;
  if (found.stat.isFile()) return rel.endsWith('/') ? null : found;
  if (found.stat.isDirectory() && rel.endsWith('/')) {
    const index = await realStat(rootReal, path.join(target, 'index.html'));
    return index && index.stat.isFile() ? index : null;
  }
  return null; // directories are never listed; sockets, fifos, devices never served
}

async function realStat(rootReal, target) {
  try {
    const real = await fs.promises.realpath(target);
    if (!isInside(rootReal, real)) return null;
    return { file: real, stat: await fs.promises.stat(real) };
  } catch {
    return null; // missing, unreadable, a loop of symlinks: all "not found"
  }
}
