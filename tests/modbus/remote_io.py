#!/usr/bin/python3
"""A Modbus TCP remote I/O for the tests: Debian's python3-pymodbus (3.0) as the server edmplc's
modbus driver talks to. Addresses are 0-based (zero_mode), 1000 of each table.

  remote_io.py --port P
prints "READY P" once it listens; then reads commands on stdin, one a line:
  set di|co|ir|hr ADDR VALUE   write a value (registers: 0..65535) into the datastore
  get di|co|ir|hr ADDR         print "di|co|ir|hr ADDR VALUE"
  quit
Every command is answered ("ok" for set), so a test knows it took effect.
"""
import argparse
import asyncio
import sys

from pymodbus.datastore import (ModbusSequentialDataBlock, ModbusServerContext,
                                ModbusSlaveContext)
from pymodbus.server.async_io import ModbusTcpServer

FC = {"co": 1, "di": 2, "hr": 3, "ir": 4}


async def control(store, server):
    loop = asyncio.get_running_loop()
    while True:
        line = await loop.run_in_executor(None, sys.stdin.readline)
        if not line:
            break
        words = line.split()
        if not words:
            continue
        if words[0] == "quit":
            break
        try:
            table, addr = words[1], int(words[2])
            if words[0] == "set":
                store.setValues(FC[table], addr, [int(words[3])])
                print("ok", flush=True)
            elif words[0] == "get":
                print(table, addr, int(store.getValues(FC[table], addr, 1)[0]), flush=True)
            else:
                print("error unknown command", flush=True)
        except (IndexError, KeyError, ValueError) as e:
            print("error", e, flush=True)
    await server.shutdown()


async def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--port", type=int, required=True)
    args = ap.parse_args()
    store = ModbusSlaveContext(di=ModbusSequentialDataBlock(0, [0] * 1000),
                               co=ModbusSequentialDataBlock(0, [0] * 1000),
                               hr=ModbusSequentialDataBlock(0, [0] * 1000),
                               ir=ModbusSequentialDataBlock(0, [0] * 1000), zero_mode=True)
    context = ModbusServerContext(slaves=store, single=True)
    server = ModbusTcpServer(context, address=("127.0.0.1", args.port), allow_reuse_address=True)
    serving = asyncio.create_task(server.serve_forever())
    await server.serving
    print("READY", args.port, flush=True)
    await control(store, server)
    serving.cancel()


if __name__ == "__main__":
    asyncio.run(main())
