#!/usr/bin/env node
// Validates a glTF 2.0 file (.glb or .gltf) with the Khronos glTF-Validator installed in
// web/node_modules, prints one summary line (and every error and warning), and exits
//   0  no error (and, with --strict, no warning either),
//   1  errors (or warnings with --strict),
//   2  usage error, unreadable file, or the validator could not run.
// Usage: node tests/tools/validate_gltf.mjs [--strict] [--allow-external] FILE...
// --allow-external: images and buffers named by a relative URI are read beside the file (the
// tiles of `python3 -m tailor.tiles` name one shared texture); otherwise they are an error.
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const validatorPath = path.resolve(here, '../../web/node_modules/gltf-validator/module.mjs');

const args = process.argv.slice(2);
const strict = args.includes('--strict');
const allowExternal = args.includes('--allow-external');
const files = args.filter((a) => a !== '--strict' && a !== '--allow-external');
if (files.length === 0) {
  console.error('usage: node tests/tools/validate_gltf.mjs [--strict] FILE...');
  process.exit(2);
}

let validator;
try {
  validator = await import(pathToFileURL(validatorPath).href);
} catch (error) {
  console.error(`validate_gltf: cannot load gltf-validator from ${validatorPath}: ${error}`);
  process.exit(2);
}

let failed = false;
for (const file of files) {
  let bytes;
  try {
    bytes = new Uint8Array(await readFile(file));
  } catch (error) {
    console.error(`validate_gltf: ${file}: ${error.message}`);
    process.exit(2);
  }
  let report;
  try {
    report = await validator.validateBytes(bytes, {
      uri: path.basename(file),
      maxIssues: 0,  // 0 = no limit
      // External resources are fetched only when asked: tailor's single files are self-contained.
      externalResourceFunction: (uri) => (allowExternal && !/^[a-z]+:|^\//i.test(uri)
        ? readFile(path.join(path.dirname(file), decodeURIComponent(uri))).then((b) => new Uint8Array(b))
        : Promise.reject(`external resource ${uri} not allowed`)),
    });
  } catch (error) {
    console.error(`validate_gltf: ${file}: validator failed: ${error}`);
    process.exit(2);
  }
  const issues = report.issues;
  console.log(`${file}: errors ${issues.numErrors} warnings ${issues.numWarnings} ` +
              `infos ${issues.numInfos} hints ${issues.numHints}`);
  for (const message of issues.messages) {
    const severity = ['error', 'warning', 'info', 'hint'][message.severity] ?? String(message.severity);
    if (message.severity <= 1 || process.env.VALIDATE_GLTF_VERBOSE) {
      console.log(`  ${severity} ${message.code} ${message.pointer ?? ''}: ${message.message}`);
    }
  }
  if (issues.numErrors > 0 || (strict && issues.numWarnings > 0)) failed = true;
}
process.exit(failed ? 1 : 0);
