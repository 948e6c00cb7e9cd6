#!/bin/sh
exec sleep 777
