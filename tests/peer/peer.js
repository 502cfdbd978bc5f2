#!/usr/bin/env node
'use strict';
// An independent CANopen peer for the daemon's tests: node-canopen's
// protocol stack (SDO server, PDO, NMT, heartbeat, EMCY; written by others)
// for every node, behind a bridge to the daemon's `unix:` CAN transport.
// Only the device behaviour is scripted here: the CiA 402 drive
// (cia402_drive.js) and the CiA 406 encoder, which counts its drive's axis.
//
//   node peer.js --socket <path> [--winches 1:11,2:12,...] [--frame-log <file>]
//                [--encoder-tpdos 4|2] [--rtr-fixed] [--no-type-255] [--rpm]
//                [--counts-per-rev N] [--encoder-range N] [--encoder-offset N]
//                [--mode-delay-ms N] [--watch-stdin]
//
// Prints "ready <socket>" once it listens; exits on SIGTERM, or at the end
// of its stdin with --watch-stdin.

const { Device } = require('canopen');
const { Bridge } = require('./bridge');
const { Cia402Drive } = require('./cia402_drive');
const { driveDictionary, encoderDictionary } = require('./dictionary');

function parseArgs(argv) {
    const args = {
        socket: null, winches: '1:11,2:12,3:13,4:14', frameLog: null, encoderTpdos: 4, rtrFixed: false,
        noType255: false, rpm: false, watchStdin: false, countsPerRev: 4096, maxMotorRpm: 10000, encoderRange: 1 << 26,
        modeDelayMs: 0, tickMs: 2, encoderOffset: 1000000,
    };
    const flags = { '--watch-stdin': 'watchStdin', '--rtr-fixed': 'rtrFixed', '--no-type-255': 'noType255', '--rpm': 'rpm' };
    const values = {
        '--socket': 'socket', '--winches': 'winches', '--frame-log': 'frameLog', '--encoder-tpdos': 'encoderTpdos',
        '--counts-per-rev': 'countsPerRev', '--encoder-range': 'encoderRange', '--mode-delay-ms': 'modeDelayMs',
        '--encoder-offset': 'encoderOffset',
    };
    for (let i = 0; i < argv.length; ++i) {
        if (flags[argv[i]]) args[flags[argv[i]]] = true;
        else if (values[argv[i]] && i + 1 < argv.length) args[values[argv[i]]] = argv[++i];
        else throw new Error(`unknown or incomplete option ${argv[i]}`);
    }
    for (const key of ['encoderTpdos', 'countsPerRev', 'encoderRange', 'modeDelayMs', 'encoderOffset'])
        args[key] = Number(args[key]);
    if (!args.socket) throw new Error('--socket <path> is required');
    if (args.encoderTpdos < 1 || args.encoderTpdos > 4) throw new Error('--encoder-tpdos must be 1..4');
    args.pairs = args.winches.split(',').map((pair) => pair.split(':').map(Number));
    return args;
}

function main() {
    const args = parseArgs(process.argv.slice(2));
    const bridge = new Bridge({ socketPath: args.socket, frameLogPath: args.frameLog });
    const winches = [];
    for (const [driveId, encoderId] of args.pairs) {
        const drive = new Device({ id: driveId, eds: driveDictionary(driveId, args), loopback: false });
        bridge.addDevice(drive);
        const behaviour = new Cia402Drive(drive, args);
        let encoder = null;
        if (encoderId) {
            encoder = new Device({ id: encoderId, eds: encoderDictionary(encoderId, args, args.encoderRange) });
            bridge.addDevice(encoder);
        }
        winches.push({ drive, behaviour, encoder });
    }
    for (const { drive, encoder } of winches) {
        drive.start();
        if (encoder) encoder.start();
    }

    // The axes run on a fixed tick measured with the monotonic clock.
    let last = process.hrtime.bigint();
    const startNs = last;
    const timer = setInterval(() => {
        const now = process.hrtime.bigint();
        const dt = Number(now - last) / 1e9;
        last = now;
        const nowMs = Number(now - startNs) / 1e6;
        for (const { behaviour, encoder } of winches) {
            behaviour.step(dt);
            if (encoder) {
                // The cable encoder counts the drum the drive turns (one
                // count per drive count) from its offset, wrapping at its
                // total measuring range as CiA 406 0x6004 does.
                const range = args.encoderRange;
                const counts = Math.round(behaviour.position) + args.encoderOffset;
                encoder.eds.getEntry(0x6004).value = ((counts % range) + range) % range;
            }
            behaviour.sendProfileTpdos(nowMs);
        }
    }, args.tickMs);

    const stop = () => {
        clearInterval(timer);
        for (const { drive, encoder } of winches) {
            drive.stop();
            if (encoder) encoder.stop();
        }
        bridge.close();
        process.exit(0);
    };
    process.on('SIGTERM', stop);
    process.on('SIGINT', stop);
    if (args.watchStdin) {
        // The test holds the other end: the peer goes when the test does.
        process.stdin.on('end', stop);
        process.stdin.resume();
    }
    bridge.listen(() => process.stdout.write(`ready ${args.socket}\n`));
}

main();
